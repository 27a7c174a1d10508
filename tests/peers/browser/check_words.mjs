// The operator page in the station's language and in the engineer's choice (issue 36), in
// Debian's chromium: a station configured for one language starts locked out; a scanner's
// serial is refused (ERROR), the master parts unlock it, a bad rotor FAILs. The page must
// speak the station's language with no missing word, sound a cue on the new FAIL and ERROR,
// and keep the verdict, the instruction and the failing measurements inside 1280x800. Then
// the page is opened in each language (?lang=): no raw catalogue key on screen, no missing
// word, and every reason code and cause the station can emit (argv) turned into that
// language's instruction, each fitting the screen.
// Usage: node check_words.mjs BASE_URL ARTIFACT_DIR LOCKED GOOD_MASTER LIMIT_MASTER BAD KEYS_JSON LANGS
// Prints one JSON object; exit code 1 with {"error": ...} when a step does not happen.
import { runCheck } from "./common.mjs";

const [base, artifacts, lockedSerial, goodMaster, limitMaster, badSerial, keysJson, langs] = process.argv.slice(2);
const KEYS = JSON.parse(keysJson);  // reason codes and causes, as the catalogue names them
const FINAL = ["PASS", "FAIL", "ERROR", "ABORTED"];
const out = { languages: {} };

async function scan(page, serial) {
  await page.keyboard.type(serial, { delay: 5 });
  await page.keyboard.press("Enter");
}

async function waitForStored(page, serial) {
  await page.waitForFunction(([s, cls]) => document.getElementById("serial").textContent === s &&
                                           cls.some(c => document.getElementById("verdict").classList.contains(c)),
                             [serial, FINAL], { timeout: 30000 });
  await page.waitForFunction(() => document.querySelectorAll("#measurements tr[data-name]").length > 0, null,
                             { timeout: 20000 });
}

// What the operator sees: verdict, instruction, reasons, and whether each lies inside the
// viewport with the page unscrolled; the failing measurement rows likewise.
function screen() {
  const inside = e => { const r = e.getBoundingClientRect(); return r.bottom <= innerHeight && r.right <= innerWidth && r.top >= 0; };
  const v = document.getElementById("verdict"), i = document.getElementById("instruction");
  const failing = [...document.querySelectorAll("#measurements tr[data-name]")].filter(r => r.cells[3].classList.contains("FAIL"));
  return {
    lang: document.documentElement.lang, verdict: v.textContent, verdict_class: v.className,
    verdict_fits: v.scrollWidth <= v.clientWidth, verdict_inside: inside(v),
    instruction: i.hidden ? "" : i.textContent, instruction_key: i.dataset.key || "",
    instruction_inside: i.hidden || inside(i),
    reasons: [...document.querySelectorAll("#reasons li")].map(li => li.querySelector(".what").textContent),
    failing: failing.map(r => ({ name: r.dataset.name, label: r.cells[0].textContent, inside: inside(r) })),
    scrolled: document.scrollingElement.scrollTop, missing: document.body.dataset.missingWords || "",
    cues: document.body.dataset.verdictCues || "",
  };
}

// Text on screen that looks like a catalogue key ("ui.start", "do.interlock.door_open") or a
// placeholder left unfilled ("{serial}").
function rawKeys() {
  const text = document.body.innerText + " " + document.title + " " +
      [...document.querySelectorAll("[aria-label],[placeholder]")].map(e => (e.getAttribute("aria-label") || "") + " " + (e.getAttribute("placeholder") || "")).join(" ");
  return [...new Set(text.match(/\b(ui|outcome|state|measurement|what|do|not_ready)\.[a-z_]+(\.[a-z_]+)?\b|\{[a-z0-9_]+\}/g) || [])];
}

// Every code and cause, rendered as an ERROR in the live page: the instruction shown, and
// whether it and the verdict fit the screen. The page's own state is restored after.
function everyInstruction(keys) {
  const result = {};
  for (const key of keys) {
    const dot = key.indexOf(".");
    const reason = dot < 0 ? { code: key, text: "technical text of " + key }
        : { code: key.slice(0, dot), cause: key, text: "technical text of " + key };
    renderOutcome("ERROR", "WORDS-1", [reason]);
    const i = document.getElementById("instruction"), r = i.getBoundingClientRect();
    const what = document.querySelector("#reasons li .what").textContent;
    result[key] = { instruction: i.textContent, what, inside: !i.hidden && r.bottom <= innerHeight,
                    missing: document.body.dataset.missingWords || "" };
  }
  return result;
}

// A door opened during the test with the rotor left clamped: the do-not-touch instruction
// goes first, whatever came before it; a reason stored as a plain string (before codes) reads
// as "legacy".
function priorities() {
  renderOutcome("ERROR", "WORDS-2", [
      { code: "interlock", cause: "interlock.lost_during_excitation", text: "interlock lost during excitation: door open" },
      { code: "interlock", cause: "fixture.clamp_left_closed", text: "clamp left as it is: door open" }]);
  const clamped = document.getElementById("instruction").dataset.key;
  renderOutcome("ERROR", "WORDS-3", ["an old reason"]);
  return { clamped, legacy: document.getElementById("instruction").dataset.key,
           legacy_what: document.querySelector("#reasons li .what").textContent };
}

await runCheck(out, async browser => {
  const context = await browser.newContext({ viewport: { width: 1280, height: 800 }, locale: "en-GB" });
  const page = await context.newPage();
  const errors = [];
  page.on("pageerror", e => errors.push(String(e)));
  page.on("console", m => { if (m.type() === "error") errors.push("console: " + m.text()); });
  await page.goto(base + "/", { timeout: 20000 });
  await page.waitForSelector("#lockout:not([hidden])", { timeout: 20000 });
  out.station_language = await page.evaluate(() => document.documentElement.lang);

  await scan(page, lockedSerial);
  await page.waitForFunction(s => document.getElementById("serial").textContent === s &&
                                  document.getElementById("verdict").classList.contains("ERROR"), lockedSerial,
                             { timeout: 30000 });
  out.error = await page.evaluate(screen);
  await page.screenshot({ path: `${artifacts}/words-station-error.png` });
  for (const serial of [goodMaster, limitMaster]) {
    await scan(page, serial);
    await waitForStored(page, serial);
  }
  await page.waitForSelector("#lockout", { state: "hidden", timeout: 10000 });
  await scan(page, badSerial);
  await waitForStored(page, badSerial);
  out.fail = await page.evaluate(screen);
  out.fail.raw_keys = await page.evaluate(rawKeys);
  await page.screenshot({ path: `${artifacts}/words-station-fail.png` });

  for (const lang of langs.split(",")) {
    await page.goto(`${base}/?lang=${lang}`, { timeout: 20000 });
    await waitForStored(page, badSerial);
    await page.waitForFunction(() => document.getElementById("connection").className === "online", null,
                               { timeout: 10000 });
    const shown = await page.evaluate(screen);
    shown.raw_keys = await page.evaluate(rawKeys);
    await page.screenshot({ path: `${artifacts}/words-${lang}-fail-1280x800.png` });
    shown.instructions = await page.evaluate(everyInstruction, KEYS);
    shown.priorities = await page.evaluate(priorities);
    shown.missing_after = await page.evaluate(() => document.body.dataset.missingWords || "");
    out.languages[lang] = shown;
  }
  out.page_errors = errors;
});
