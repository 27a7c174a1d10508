// Drives Debian's chromium (headless, through playwright-core) against the operator page of a
// station that starts locked out (self-checks configured): a keyboard-wedge scanner types
// serials into the focused field (keyboard only, no clicks) and every result is read back
// from the page. At 1280x800 and 1920x1080 it keeps screenshots of lockout, ERROR, TESTING,
// PASS and FAIL, measures whether the verdict overflows its box, and runs axe-core in the page.
// Usage: node check_operator.mjs BASE_URL ARTIFACT_DIR LOCKED GOOD_MASTER LIMIT_MASTER GOOD BAD
// Prints one JSON object; exit code 1 with {"error": ...} when a step does not happen.
import { runCheck, seriousViolations } from "./common.mjs";

const [base, artifacts, lockedSerial, goodMaster, limitMaster, goodSerial, badSerial] = process.argv.slice(2);
const SIZES = [[1280, 800], [1920, 1080]];
const FINAL = ["PASS", "FAIL", "ERROR", "ABORTED"];
const out = { states: {}, screenshots: [] };


// The verdict box at this size: does the word fit, and how large is it.
function verdictBox() {
  const v = document.getElementById("verdict");
  const style = getComputedStyle(v);
  return { text: v.textContent, scroll: v.scrollWidth, client: v.clientWidth,
           fits: v.scrollWidth <= v.clientWidth, font_px: parseFloat(style.fontSize),
           background: style.backgroundColor };
}

// Every word the lamp can show, put into the live page's verdict box at this size.
function everyWord() {
  const v = document.getElementById("verdict");
  const saved = [v.className, v.textContent];
  const result = {};
  for (const [cls, word] of [["PASS", "PASS"], ["FAIL", "FAIL"], ["ERROR", "ERROR"],
                             ["ABORTED", "ABORTED"], ["RUNNING", "TESTING"]]) {
    v.className = "verdict " + cls;
    v.textContent = word;
    result[word] = { scroll: v.scrollWidth, client: v.clientWidth, fits: v.scrollWidth <= v.clientWidth,
                     background: getComputedStyle(v).backgroundColor };
  }
  [v.className, v.textContent] = saved;
  return result;
}

// Screenshots at both sizes (kept as test artifacts), the verdict box at each, and axe at each.
async function capture(page, name, { axe = true } = {}) {
  const state = { sizes: {} };
  for (const [w, h] of SIZES) {
    await page.setViewportSize({ width: w, height: h });
    const size = { verdict: await page.evaluate(verdictBox) };
    const path = `${artifacts}/operator-${name}-${w}x${h}.png`;
    await page.screenshot({ path });
    out.screenshots.push(path);
    if (axe) size.axe = await seriousViolations(page);
    state.sizes[`${w}x${h}`] = size;
  }
  state.instruction = (await page.isVisible("#instruction")) ? await page.textContent("#instruction") : "";
  state.reasons = await page.locator("#reasons li").allTextContents();
  state.lockout = (await page.isVisible("#lockout")) ? await page.textContent("#lockout") : "";
  state.focus = await page.evaluate(() => document.activeElement && document.activeElement.id);
  out.states[name] = state;
  return state;
}

// The id of the focused element once the scanner's field has it (within 2 s), or what has it.
async function focusedSoon(page) {
  await page.waitForFunction(() => document.activeElement && document.activeElement.id === "scan", null,
                             { timeout: 2000 }).catch(() => {});
  return page.evaluate(() => document.activeElement && document.activeElement.id);
}

const text = (page, sel) => page.evaluate(s => document.querySelector(s).textContent, sel);

// The page shows this serial with one of these outcomes (class of #verdict).
async function waitFor(page, serial, classes, timeout = 30000) {
  await page.waitForFunction(([s, cls]) => document.getElementById("serial").textContent === s &&
                                           cls.some(c => document.getElementById("verdict").classList.contains(c)),
                             [serial, classes], { timeout });
}

// The scanner: types the serial and Enter into whatever has the focus, as a keyboard wedge does.
async function scan(page, serial) {
  await page.keyboard.type(serial, { delay: 5 });
  await page.keyboard.press("Enter");
}

// The final verdict of a stored test, once its curve has arrived.
async function waitForStored(page, serial) {
  await waitFor(page, serial, FINAL);
  await page.waitForSelector(`#plot[data-serial="${serial}"] path.measured`, { timeout: 20000 });
  await page.waitForFunction(() => document.querySelectorAll("#measurements tr[data-name]").length > 0 &&
                                  document.getElementById("tested").textContent !== "", null, { timeout: 20000 });
}

await runCheck(out, async browser => {
  const context = await browser.newContext({ viewport: { width: SIZES[0][0], height: SIZES[0][1] },
                                             locale: "en-GB", timezoneId: "Asia/Kolkata" });
  const page = await context.newPage();
  const errors = [];
  page.on("pageerror", e => errors.push(String(e)));
  page.on("console", m => { if (m.type() === "error") errors.push("console: " + m.text()); });
  const outside = [];  // the page must not reach beyond the station
  page.on("request", r => { if (!r.url().startsWith(base)) outside.push(r.url()); });
  await page.goto(base + "/", { timeout: 20000 });
  await page.waitForSelector("#lockout:not([hidden])", { timeout: 20000 });
  out.focus_on_load = await focusedSoon(page);
  await capture(page, "lockout");

  // Locked: a production serial is refused, ERROR, with the recipe's instruction.
  await scan(page, lockedSerial);
  await waitFor(page, lockedSerial, FINAL);
  await capture(page, "error");

  // The operator signs in (the one place a click is allowed); Enter hands the focus back.
  await page.click("#operator-id");
  await page.keyboard.type("op-17");
  await page.keyboard.press("Enter");
  await page.click("#shift");
  await page.keyboard.type("B");
  await page.keyboard.press("Enter");
  out.focus_after_sign_in = await focusedSoon(page);

  // The master parts unlock the station.
  await scan(page, goodMaster);
  await waitForStored(page, goodMaster);
  out.good_master = await text(page, "#verdict");
  await scan(page, limitMaster);
  await waitForStored(page, limitMaster);
  out.limit_master = await text(page, "#verdict");
  out.limit_master_instruction = await text(page, "#instruction");
  await page.waitForSelector("#lockout", { state: "hidden", timeout: 10000 });

  // A click elsewhere must not take the scanner's field away.
  await page.click("#history-title");
  out.focus_after_click = await focusedSoon(page);
  await scan(page, goodSerial);
  await waitFor(page, goodSerial, ["RUNNING"]);
  const testing = await capture(page, "testing", { axe: false });
  testing.still_running = await page.evaluate(() => document.getElementById("verdict").classList.contains("RUNNING"));
  await waitForStored(page, goodSerial);
  const pass = await capture(page, "pass");
  pass.verdict = await text(page, "#verdict");
  pass.tested = await text(page, "#tested");
  pass.measurements = await page.$$eval("#measurements tr[data-name]", rows => rows.map(r => ({
    name: r.dataset.name, label: r.cells[0].textContent, value: r.cells[1].textContent,
    limits: r.cells[2].textContent, result: r.cells[3].textContent })));
  pass.chart = await page.evaluate(() => {
    const svg = document.getElementById("plot");
    const order = [...svg.children].map(e => e.getAttribute("class")).filter(Boolean);
    const win = svg.querySelector("rect.window");
    return { order, window: win && { lo: Number(win.dataset.lo), hi: Number(win.dataset.hi) },
             masks: svg.querySelectorAll("polygon.mask").length,
             model_points: Number(svg.querySelector("path.model")?.dataset.points || 0),
             measured_points: Number(svg.querySelector("path.measured")?.dataset.points || 0),
             legend: [...document.querySelectorAll("#legend .key")].map(k => [k.classList[1], k.textContent]) };
  });
  pass.history = await page.$$eval("#history tr", rows => rows.slice(1).map(r => ({
    serial: r.cells[0].textContent, outcome: r.cells[1].textContent,
    utc: r.cells[3].dataset.utc, shown: r.cells[3].textContent })));

  await scan(page, badSerial);
  await waitForStored(page, badSerial);
  const fail = await capture(page, "fail");
  fail.verdict = await text(page, "#verdict");
  fail.attempt = await text(page, "#attempt");
  // Retest marking: the same serial again is "retest 2 of 3" (the recipe allows 3 tests).
  await scan(page, badSerial);
  await page.waitForFunction(() => document.getElementById("attempt").textContent.startsWith("retest 2"),
                             null, { timeout: 30000 });
  out.retest = { attempt: await text(page, "#attempt"), verdict: await text(page, "#verdict") };

  for (const [w, h] of SIZES) {
    await page.setViewportSize({ width: w, height: h });
    out[`words_${w}x${h}`] = await page.evaluate(everyWord);
  }
  out.outside_requests = outside;
  out.page_errors = errors;
});
