// Drives Debian's chromium (headless, through playwright-core) against the operator page of a
// station whose recipe measures several phase pairs and bounds |Z| as well as Re Z: reads back
// what each chart panel draws (every pair's measured curve and fitted model, the masks of each
// quantity, the resonance window) and the legend, keeps screenshots at 1280x800 and 1920x1080
// and runs axe-core in the page.
// Usage: node check_curves.mjs BASE_URL ARTIFACT_DIR SERIAL
// Prints one JSON object; exit code 1 with {"error": ...} when the page does not show it.
import { runCheck, seriousViolations } from "./common.mjs";

const [base, artifacts, serial] = process.argv.slice(2);
const out = { sizes: {}, screenshots: [] };

// What one panel draws, by element: curves with their pair, masks with their bound.
function panel(id) {
  const svg = document.getElementById(id);
  const paths = cls => [...svg.querySelectorAll("path." + cls)].map(p => ({
    pair: p.dataset.pairName, points: Number(p.dataset.points) }));
  const win = svg.querySelector("rect.window");
  const box = svg.getBoundingClientRect();
  return { hidden: svg.hasAttribute("hidden") || getComputedStyle(svg).display === "none", height_px: box.height, serial: svg.dataset.serial || "",
           label: svg.getAttribute("aria-label"), measured: paths("measured"), model: paths("model"),
           masks: [...svg.querySelectorAll("polygon.mask")].map(p => ({ mask: p.dataset.mask, bound: p.dataset.bound })),
           window: win && { lo: Number(win.dataset.lo), hi: Number(win.dataset.hi) },
           f0_lines: svg.querySelectorAll("line.f0").length,
           last: [...svg.children].map(e => e.getAttribute("class")).filter(Boolean).pop() };
}

await runCheck(out, async browser => {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  const errors = [];
  page.on("pageerror", e => errors.push(String(e)));
  page.on("console", m => { if (m.type() === "error") errors.push("console: " + m.text()); });
  await page.goto(base + "/", { timeout: 20000 });
  await page.waitForSelector(`#plot[data-serial="${serial}"] path.measured`, { timeout: 30000 });
  await page.waitForSelector(`#plot-abs[data-serial="${serial}"] path.measured`, { timeout: 10000 });
  out.re = await page.evaluate(panel, "plot");
  out.abs = await page.evaluate(panel, "plot-abs");
  out.legend = await page.$$eval("#legend .key", keys => keys.map(k => [k.classList[1], k.textContent, k.dataset.pair ?? null]));
  out.measurements = await page.$$eval("#measurements tr[data-name]", rows => rows.map(r => r.dataset.name));
  out.curve_note = await page.textContent("#curve-note");
  for (const [w, h] of [[1280, 800], [1920, 1080]]) {
    await page.setViewportSize({ width: w, height: h });
    const path = `${artifacts}/phase-pairs-${w}x${h}.png`;
    await page.screenshot({ path, fullPage: true });
    out.screenshots.push(path);
    out.sizes[`${w}x${h}`] = {
      abs_height_px: await page.evaluate(() => document.getElementById("plot-abs").getBoundingClientRect().height),
      axe: await seriousViolations(page),
    };
  }
  out.page_errors = errors;
});
