// What every browser check shares: Debian's chromium (headless, through playwright-core), the
// serious and critical violations axe-core finds in a page, and the one JSON object each
// check prints for its C++ test (tests/peers/operator_page_test.cc).
import { createRequire } from "node:module";
import { chromium } from "playwright-core";

const axePath = createRequire(import.meta.url).resolve("axe-core/axe.min.js");

// Runs `check(browser)` in a fresh chromium, then prints `out` as one JSON line; when a step
// throws, prints {"error", "partial": out} instead and sets exit code 1.
export async function runCheck(out, check) {
  const browser = await chromium.launch({
    executablePath: "/usr/bin/chromium",
    args: ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
           "--disable-background-networking", "--disable-component-update", "--disable-sync"],
  });
  try {
    await check(browser);
    console.log(JSON.stringify(out));
  } catch (e) {
    console.log(JSON.stringify({ error: String(e), partial: out }));
    process.exitCode = 1;
  } finally {
    await browser.close();
  }
}

// axe-core run in the page: its serious and critical violations, by rule, with their targets.
export async function seriousViolations(page) {
  if (!(await page.evaluate(() => typeof window.axe === "object")))
    await page.addScriptTag({ path: axePath });
  const r = await page.evaluate(() => window.axe.run(document, { resultTypes: ["violations"] }));
  return r.violations.filter(v => v.impact === "serious" || v.impact === "critical")
      .map(v => ({ id: v.id, impact: v.impact, help: v.help,
                   targets: v.nodes.map(n => n.target.join(" ")).slice(0, 5) }));
}
