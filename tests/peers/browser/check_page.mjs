// Drives Debian's chromium (headless, through playwright-core) against the operator page:
// checks that the stored verdict, the serial and the measured curve against its mask are
// shown, then starts a second test over the API and checks the page follows it live (SSE).
// Usage: node check_page.mjs BASE_URL SCREENSHOT.png SERIAL1 SERIAL2
// Prints one JSON object; exit code 1 with {"error": ...} when the page does not show it.
import { runCheck } from "./common.mjs";

const [base, shot, serial1, serial2] = process.argv.slice(2);
const out = {};
await runCheck(out, async browser => {
  const page = await browser.newPage({ viewport: { width: 1400, height: 900 } });
  const errors = [];
  page.on("pageerror", e => errors.push(String(e)));
  await page.goto(base + "/", { timeout: 20000 });
  const finalVerdict = "#verdict.PASS, #verdict.FAIL, #verdict.ERROR, #verdict.ABORTED";
  await page.waitForSelector(finalVerdict, { timeout: 20000 });
  await page.waitForFunction(s => document.getElementById("serial").textContent === s, serial1,
                             { timeout: 20000 });
  await page.waitForSelector("#plot path.measured", { timeout: 20000 });
  out.first = {
    verdict: await page.textContent("#verdict"),
    serial: await page.textContent("#serial"),
    points: Number(await page.getAttribute("#plot path.measured", "data-points")),
    model: await page.locator("#plot path.model").count(),
    masks: await page.locator("#plot polygon.mask").count(),
    measurements: await page.locator("#measurements tr").count() - 1,
    history: await page.locator("#history tr").count() - 1,
    simulation: (await page.isVisible("#simulation")) ? await page.textContent("#simulation") : "",
  };
  // A new test started elsewhere shows up without a reload.
  const res = await fetch(base + "/api/tests", { method: "POST", body: JSON.stringify({ serial: serial2 }),
                                                 headers: { "Content-Type": "application/json" } });
  if (res.status !== 202) throw new Error("POST /api/tests answered " + res.status);
  await page.waitForFunction(s => document.getElementById("serial").textContent === s &&
                                  /PASS|FAIL|ERROR|ABORTED/.test(document.getElementById("verdict").className),
                             serial2, { timeout: 30000 });
  await page.waitForFunction(s => document.getElementById("curve-note").textContent.includes(s),
                             serial2, { timeout: 20000 });
  out.second = { verdict: await page.textContent("#verdict"), serial: await page.textContent("#serial"),
                 connection: await page.textContent("#connection") };
  await page.screenshot({ path: shot });
  out.page_errors = errors;
});
