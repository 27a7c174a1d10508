// The operator page of a station of two motor types (tests/peers/operator_page_test.cc): the
// page offers the station's variants; a serial no prefix rule claims is started with the type
// the operator picks, and the station records that type.
// Usage: node check_variant.mjs BASE_URL VARIANT SERIAL
// Prints one JSON object; exit code 1 with {"error": ...} when a step does not happen.
import { runCheck } from "./common.mjs";

const [base, variant, serial] = process.argv.slice(2);
const out = {};
await runCheck(out, async browser => {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  await page.goto(base + "/", { timeout: 20000 });
  await page.waitForFunction(() => document.getElementById("connection").textContent === "live", null,
                             { timeout: 20000 });
  await page.waitForFunction(() => !document.getElementById("variant-row").hidden, null,
                             { timeout: 10000 });
  out.options = await page.$$eval("#variant option", os => os.map(o => o.value));
  out.labels = await page.$$eval("#variant option", os => os.map(o => o.textContent));
  await page.selectOption("#variant", variant);
  await page.click("#scan");
  await page.keyboard.type(serial);
  await page.keyboard.press("Enter");
  await page.waitForFunction(s => document.getElementById("serial").textContent === s &&
                                  /PASS|FAIL|ERROR|ABORTED/.test(document.getElementById("verdict").className),
                             serial, { timeout: 30000 });
  out.started = await page.textContent("#start-status");
  out.verdict = await page.textContent("#verdict");
});
