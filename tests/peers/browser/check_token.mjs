// The operator page of a station with tokens (tests/peers/operator_page_test.cc): a scanned
// serial is refused (401), the page asks for the operator's token; once it is typed, the
// same scan starts the test and the page shows its verdict.
// Usage: node check_token.mjs BASE_URL TOKEN SERIAL
// Prints one JSON object; exit code 1 with {"error": ...} when a step does not happen.
import { runCheck } from "./common.mjs";

const [base, token, serial] = process.argv.slice(2);
const out = {};
const focused = page => page.evaluate(() => document.activeElement && document.activeElement.id);
await runCheck(out, async browser => {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  await page.goto(base + "/", { timeout: 20000 });
  await page.waitForFunction(() => document.getElementById("connection").textContent === "live", null,
                             { timeout: 20000 });
  out.token_row_at_start = await page.isVisible("#token-row");
  await page.keyboard.type(serial);
  await page.keyboard.press("Enter");
  await page.waitForSelector("#start-status.problem", { timeout: 10000 });
  out.refused = await page.textContent("#start-status");
  out.token_row_after_refusal = await page.isVisible("#token-row");
  await page.click("#token");
  await page.keyboard.type(token);
  await page.keyboard.press("Enter");
  out.focus_after_token = await focused(page);
  await page.keyboard.type(serial);
  await page.keyboard.press("Enter");
  await page.waitForFunction(s => document.getElementById("serial").textContent === s &&
                                  /PASS|FAIL|ERROR|ABORTED/.test(document.getElementById("verdict").className),
                             serial, { timeout: 30000 });
  out.verdict = await page.textContent("#verdict");
  out.started = await page.textContent("#start-status");
});
