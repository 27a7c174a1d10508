// Live health on the operator page (tests/peers/operator_page_test.cc): the fixture
// controller stops and returns while the station idles, then the daemon hangs, dies and is
// started again, and the page must follow each within its bound. The C++ test does each step
// when this script asks for it: the script prints "step: NAME", the test acts and writes
// SYNC_DIR/NAME.done holding the wall-clock time of the act in ms (Date.now()'s clock), from
// which the page's reaction time is measured.
// Usage: node check_health.mjs BASE_URL SYNC_DIR ARTIFACT_DIR SERIAL_1 SERIAL_2 SERIAL_3
// Prints step lines, then one JSON object; exit code 1 with {"error": ...} when a step fails.
import fs from "node:fs";
import { runCheck } from "./common.mjs";

const [base, sync, artifacts, serial1, serial2, serial3] = process.argv.slice(2);
const out = { screenshots: [] };
const POLL = { polling: 20, timeout: 15000 };

// Asks the test for `name` and waits until it is done; returns when it acted (ms, wall clock).
async function step(name) {
  console.log("step: " + name);
  const file = `${sync}/${name}.done`;
  for (let i = 0; i < 1200 && !fs.existsSync(file); i++) await new Promise(r => setTimeout(r, 25));
  const acted = Number(fs.readFileSync(file, "utf8"));
  if (!(acted > 0)) throw new Error(`step ${name}: no time in ${file}`);
  return acted;
}

// Scans a serial as the keyboard-wedge scanner does and waits for its final verdict.
async function scan(page, serial) {
  await page.keyboard.type(serial);
  await page.keyboard.press("Enter");
  await page.waitForFunction(s => document.getElementById("serial").textContent === s &&
      /PASS|FAIL|ERROR|ABORTED/.test(document.getElementById("verdict").className), serial,
      { polling: 50, timeout: 60000 });
  await page.waitForFunction(s => document.getElementById("plot").dataset.serial === s, serial,
                             { polling: 50, timeout: 20000 });  // its stored record is drawn
  return page.textContent("#verdict");
}

// What the page shows about the station's link and readiness.
function linkState() {
  const $ = id => document.getElementById(id);
  const nr = $("not-ready");
  return {
    connection: $("connection").textContent,
    start_disabled: $("start").disabled,
    offline_banner: !$("offline").hidden,
    not_ready: nr.hidden ? null : { code: nr.dataset.code, text: nr.textContent },
    verdict_filter: getComputedStyle($("verdict-panel")).filter,
    start_status: $("start-status").textContent,
    start_status_problem: $("start-status").className === "problem",
    message: $("message").textContent,
    history: [...document.querySelectorAll("#history tr")].slice(1).map(r => r.cells[0].textContent),
    counts: $("counts").textContent,
  };
}

async function shot(page, name) {
  const path = `${artifacts}/health-${name}.png`;
  await page.screenshot({ path });
  out.screenshots.push(path);
}

await runCheck(out, async browser => {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  await page.goto(base + "/", { timeout: 20000 });
  await page.waitForFunction(() => document.getElementById("connection").textContent === "live", null, POLL);
  out.at_start = await page.evaluate(linkState);
  out.first = await scan(page, serial1);

  let acted = await step("stop_fixture");
  await page.waitForFunction(() => !document.getElementById("not-ready").hidden, null, POLL);
  out.fixture_lost = { ms: Date.now() - acted, ...(await page.evaluate(linkState)) };
  await shot(page, "fixture-lost");

  acted = await step("start_fixture");
  await page.waitForFunction(() => document.getElementById("not-ready").hidden, null, POLL);
  out.fixture_back = { ms: Date.now() - acted, ...(await page.evaluate(linkState)) };
  // A scan while a test runs is refused (the station tests one unit at a time), visibly and
  // audibly, and that refusal outlives the running test's verdict: the unit was not tested.
  const cues = () => page.evaluate(() => Number(document.body.dataset.cues || 0));
  const cuesBefore = await cues();
  await page.keyboard.type(serial2);
  await page.keyboard.press("Enter");
  await page.waitForFunction(s => document.getElementById("serial").textContent === s &&
      document.getElementById("verdict").classList.contains("RUNNING"), serial2, POLL);
  await page.keyboard.type(serial2 + "-B");
  await page.keyboard.press("Enter");
  await page.waitForFunction(() => document.getElementById("start-status").className === "problem", null, POLL);
  out.busy = { cues: (await cues()) - cuesBefore, ...(await page.evaluate(linkState)) };
  await page.waitForFunction(s => document.getElementById("serial").textContent === s &&
      /PASS|FAIL|ERROR|ABORTED/.test(document.getElementById("verdict").className), serial2,
      { polling: 50, timeout: 60000 });
  await page.waitForFunction(s => document.getElementById("plot").dataset.serial === s, serial2,
                             { polling: 50, timeout: 20000 });
  out.second = await page.textContent("#verdict");
  out.after_second = { page_text: await page.evaluate(() => document.body.innerText),
                       ...(await page.evaluate(linkState)) };

  // A hung daemon (SIGSTOP): the connection stays open, only the silence tells.
  acted = await step("freeze_daemon");
  await page.waitForFunction(() => document.getElementById("start").disabled &&
      document.getElementById("connection").textContent === "station offline", null, POLL);
  out.frozen = { ms: Date.now() - acted, ...(await page.evaluate(linkState)) };
  await shot(page, "offline");

  await step("kill_daemon");
  await page.keyboard.type(serial3);  // refused on the page, and the serial leaves the field
  await page.keyboard.press("Enter");
  await page.waitForFunction(() => document.getElementById("start-status").className === "problem", null, POLL);
  out.refused_offline = { scan_field: await page.inputValue("#scan"), ...(await page.evaluate(linkState)) };

  acted = await step("restart_daemon");
  await page.waitForFunction(() => document.getElementById("connection").textContent === "live", null,
                             { polling: 20, timeout: 30000 });
  await page.waitForFunction(() => document.querySelectorAll("#history tr").length > 1, null,
                             { polling: 20, timeout: 5000 }).catch(() => {});
  out.back = { ms: Date.now() - acted, ...(await page.evaluate(linkState)) };
  // The third test is started as the line PLC would, not from the page: the page's stale
  // refusal must go with its verdict.
  const started = await page.request.post(base + "/api/tests", { data: { serial: serial3 } });
  if (started.status() !== 202) throw new Error("POST /api/tests: HTTP " + started.status());
  await page.waitForFunction(s => document.getElementById("serial").textContent === s &&
      /PASS|FAIL|ERROR|ABORTED/.test(document.getElementById("verdict").className), serial3,
      { polling: 50, timeout: 60000 });
  out.third = await page.textContent("#verdict");
  out.after_third = await page.evaluate(linkState);
});
