// Drives Debian's chromium (headless, through playwright-core) against the engineer page of a
// station with stored tests: reads back the capability table and the words of every chart the
// page shows (the SVG it loaded), narrows the window to the last N tests, picks another
// measurement, reads the yield table and the Pareto's caption, the detectability table, uploads a hits CSV and gap inputs and reads the
// figures back; axe-core at 1920x1080 and 1280x800, screenshots kept.
// Usage: node check_engineer.mjs BASE_URL ARTIFACT_DIR LAST_N HITS_CSV SIM_FILE MEASURED_FILE
// Prints one JSON object; exit code 1 with {"error": ...} when a step does not happen.
import { runCheck, seriousViolations } from "./common.mjs";

const [base, artifacts, lastN, hits, sim, measured] = process.argv.slice(2);
const out = { screenshots: [] };

// What the page shows now: the capability rows and, per chart, whether the image rendered and
// the words of the SVG it shows (<title> and <desc>, drivers/io/chart.h).
async function shown(page) {
  return page.evaluate(async () => {
    const words = async img => {
      if (img.hidden || !img.src) return null;
      await img.decode().catch(() => {});
      const svg = new DOMParser().parseFromString(await (await fetch(img.src)).text(), "image/svg+xml");
      return { rendered: img.complete && img.naturalWidth > 0, url: img.dataset.url || "",
               root: svg.documentElement.nodeName,
               paths: svg.getElementsByTagName("path").length,
               title: svg.querySelector("title")?.textContent || "",
               desc: svg.querySelector("desc")?.textContent || "" };
    };
    const charts = {};
    for (const id of ["chart-imr", "chart-xbar", "chart-hist"]) charts[id] = await words(document.getElementById(id));
    const capability = [...document.querySelectorAll("#capability tr[data-name]")].map(r => ({
      name: r.dataset.name, n: Number(r.cells[2].textContent),
      cp: r.querySelector("[data-key=cp]").textContent, cpk: r.querySelector("[data-key=cpk]").textContent,
      pp: r.querySelector("[data-key=pp]").textContent, ppk: r.querySelector("[data-key=ppk]").textContent }));
    return { status: document.getElementById("window-status").textContent, charts, capability,
             options: [...document.getElementById("measurement").options].map(o => o.value) };
  });
}

async function figure(page, id) {
  await page.waitForSelector(`#${id}:not([hidden])`, { timeout: 120000 });
  return page.evaluate(async id => {
    const img = document.getElementById(id);
    await img.decode().catch(() => {});
    const text = await (await fetch(img.src)).text();
    const svg = new DOMParser().parseFromString(text, "image/svg+xml");
    return { rendered: img.naturalWidth > 0, title: svg.querySelector("title")?.textContent || "",
             desc: svg.querySelector("desc")?.textContent || "" };
  }, id);
}

await runCheck(out, async browser => {
  const page = await browser.newPage({ viewport: { width: 1920, height: 1080 } });
  const errors = [];
  page.on("pageerror", e => errors.push(String(e)));
  page.on("console", m => { if (m.type() === "error") errors.push("console: " + m.text()); });
  const outside = [];
  page.on("request", r => { if (!r.url().startsWith(base) && !r.url().startsWith("blob:")) outside.push(r.url()); });

  // The operator page links here.
  await page.goto(base + "/", { timeout: 20000 });
  out.link = await page.getAttribute("#engineer-link", "href");
  await page.click("#engineer-link");
  await page.waitForSelector("body[data-ready=true]", { timeout: 60000 });
  out.url = page.url();
  out.initial = await shown(page);
  // The yield table (per day by default) and the Pareto's caption.
  out.yield = await page.evaluate(() => ({
    rows: [...document.querySelectorAll("#yield tr[data-key]")].map(r => ({
      key: r.dataset.key, total: r.classList.contains("total"), units: Number(r.cells[1].textContent),
      first_pass: r.cells[2].textContent, final: r.cells[4].textContent })),
    pareto_caption: document.querySelector("#chart-pareto").parentElement.querySelector("figcaption").textContent,
    status: document.getElementById("yield-status").textContent }));
  out.detectability = await page.$$eval("#detectability tr[data-defect]", rows => rows.map(r => ({
    defect: r.dataset.defect, detectable: r.cells[5].textContent })));
  out.axe_1920 = await seriousViolations(page);
  let path = `${artifacts}/engineer-1920x1080.png`;
  await page.screenshot({ path, fullPage: true });
  out.screenshots.push(path);

  // The last N tests, then Q.
  await page.fill("#last", lastN);
  await page.click("#window-form button[type=submit]");
  await page.waitForFunction(n => document.getElementById("window-status").textContent.includes(`last ${n} tests`),
                             lastN, { timeout: 30000 });
  out.last = await shown(page);
  await page.selectOption("#measurement", "resonance_q");
  await page.waitForFunction(() => document.getElementById("window-status").textContent.startsWith("resonance_q:"),
                             null, { timeout: 30000 });
  out.q = await shown(page);

  // Figures from files.
  await page.setInputFiles("#pod-hits", hits);
  await page.fill("#pod-limits", "370, 420");
  await page.click("#pod-form button[type=submit]");
  out.pod = await figure(page, "pod-figure");
  out.pod_status = await page.textContent("#pod-status");
  await page.setInputFiles("#gap-sim", sim);
  await page.setInputFiles("#gap-measured", measured);
  await page.click("#gap-form button[type=submit]");
  out.gap = await figure(page, "gap-figure");
  out.gap_status = await page.textContent("#gap-status");
  path = `${artifacts}/engineer-figures-1920x1080.png`;
  await page.screenshot({ path, fullPage: true });
  out.screenshots.push(path);
  await page.setViewportSize({ width: 1280, height: 800 });
  out.axe_1280 = await seriousViolations(page);
  path = `${artifacts}/engineer-1280x800.png`;
  await page.screenshot({ path });
  out.screenshots.push(path);
  out.outside_requests = outside;
  out.page_errors = errors;
});
