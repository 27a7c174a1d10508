// Engineer page: control charts, histogram and capability of one measurement over a window of
// stored tests, yield with the Pareto of reasons over the same window, detectability of defect
// classes, and POD and gap figures from files. Every figure is the station's own SVG
// (GET /api/charts/..., /api/yield/pareto.svg, POST /api/pod.svg, /api/gap.svg), the
// same drawing the `eol` command writes; this page only asks and shows. No libraries, no
// network beyond this station.
"use strict";

// The measurements the chart route draws (analysis/qc/measurement_names.h kAll).
const CHARTED = ["resonance_f_hz", "resonance_q", "winding_r_ohm", "winding_l_h", "motional_rp_ohm",
                 "fit_chi2_per_dof", "motional_residue_ohm_per_s"];

function $(id) { return document.getElementById(id); }

function el(tag, attrs, text) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  if (text !== undefined) e.textContent = text;
  return e;
}

// The API's error as one line: {"error": {"code", "message"}} or the HTTP status.
async function failure(res) {
  const body = await res.json().catch(() => ({}));
  return (body.error && `${body.error.message} (${body.error.code})`) || "HTTP " + res.status;
}

async function getJson(url) {
  const res = await fetch(url, {cache: "no-store"});
  if (!res.ok) throw new Error(url.split("?")[0] + ": " + await failure(res));
  return res.json();
}

function num(v, digits) {
  if (v === null || v === undefined || !isFinite(v)) return "—";
  return new Intl.NumberFormat(undefined, {maximumSignificantDigits: digits || 4, useGrouping: false}).format(v);
}

function status(id, text, problem) {
  $(id).textContent = text;
  $(id).className = problem ? "problem" : "";
}

// --- The window: the newest N tests, or a time range in local time. ---

// A datetime-local value ("2026-11-25T09:30:00") as ISO 8601 with this browser's offset.
function isoWithOffset(local) {
  const t = new Date(local);
  if (isNaN(t)) return null;
  const off = -t.getTimezoneOffset(), sign = off >= 0 ? "+" : "-", abs = Math.abs(off);
  const pad = n => String(n).padStart(2, "0");
  return local.length === 16 ? local + ":00" + sign + pad(abs / 60 | 0) + ":" + pad(abs % 60)
                             : local + sign + pad(abs / 60 | 0) + ":" + pad(abs % 60);
}

// {from, to} for the API (either may be absent), and the words for it. "last N tests" starts
// at the N-th newest stored test (GET /api/tests is newest first), so the charts and the
// capability table cover the same tests.
async function windowQuery() {
  if ($("window-range").checked) {
    const q = {};
    if ($("from").value) q.from = isoWithOffset($("from").value);
    if ($("to").value) q.to = isoWithOffset($("to").value);
    return {query: q, words: `${$("from").value || "the first test"} to ${$("to").value || "now"}`};
  }
  const n = Math.max(2, Math.min(10000, Number($("last").value) || 100));
  const list = await getJson("/api/tests?limit=" + n);
  const tests = list.tests || [];
  if (!tests.length) return {query: {}, words: "no tests stored"};
  return {query: {from: tests[tests.length - 1].started_at}, words: `last ${tests.length} tests`};
}

function queryString(params) {
  const q = new URLSearchParams();
  for (const [k, v] of Object.entries(params)) if (v !== undefined && v !== null && v !== "") q.set(k, v);
  return q.toString();
}

// --- Capability and control charts of the picked measurement. ---

function fillPicker(recipes) {
  const select = $("measurement");
  const have = new Set([...select.options].map(o => o.value));
  for (const r of recipes)
    for (const m of r.measurements)
      if (CHARTED.includes(m.name) && !have.has(m.name)) {
        select.appendChild(el("option", {value: m.name}, m.name + (m.unit && m.unit !== "1" ? ` (${m.unit})` : "")));
        have.add(m.name);
      }
}

function renderCapability(report, picked) {
  const t = $("capability");
  t.replaceChildren();
  const head = el("tr");
  for (const h of ["recipe", "measurement", "n", "mean", "sd", "LSL", "USL", "Cp", "Cpk", "Pp", "Ppk",
                   "control limits"])
    head.appendChild(el("th", {scope: "col"}, h));
  t.appendChild(head);
  for (const r of report.recipes || []) {
    for (const m of r.measurements) {
      if (m.name !== picked) continue;
      const row = el("tr", {"data-name": m.name, "data-recipe": r.recipe_hash});
      const c = m.control || {};
      for (const v of [`${r.recipe_id} v${r.recipe_version}`, m.name, m.n, num(m.mean, 5), num(m.sd, 3),
                       num(m.lo, 5), num(m.hi, 5), num(m.cp, 3), num(m.cpk, 3), num(m.pp, 3), num(m.ppk, 3),
                       c.centre != null ? `${num(c.lcl, 5)} … ${num(c.ucl, 5)}` : "—"])
        row.appendChild(el("td", {}, String(v)));
      row.cells[7].dataset.key = "cp";
      row.cells[8].dataset.key = "cpk";
      row.cells[9].dataset.key = "pp";
      row.cells[10].dataset.key = "ppk";
      t.appendChild(row);
    }
  }
  $("capability-note").textContent = report.recipes && report.recipes.length
      ? `(${(report.recipes[0].measurements[0] || {}).population || ""}; Cp/Cpk within-subgroup sigma, Pp/Ppk overall)`
      : "(no production test in the window)";
  const ul = $("alarms");
  ul.replaceChildren();
  for (const a of (report.alarms || []).concat(report.spc_alarms || []))
    if (a.includes(picked)) ul.appendChild(el("li", {}, a));
}

// Loads a chart into its <img>; the route's JSON error (no units, bad parameter) goes into
// the image's caption instead.
async function showChart(img, url) {
  const caption = img.parentElement.querySelector("figcaption");
  caption.dataset.base = caption.dataset.base || caption.textContent;
  const res = await fetch(url, {cache: "no-store"});
  if (!res.ok) {
    img.hidden = true;
    img.removeAttribute("src");
    caption.textContent = caption.dataset.base + ": " + await failure(res);
    return;
  }
  const svg = await res.blob();
  if (img.src.startsWith("blob:")) URL.revokeObjectURL(img.src);
  img.src = URL.createObjectURL(svg);
  img.dataset.url = url;
  img.hidden = false;
  caption.textContent = caption.dataset.base;
}

async function refresh() {
  status("window-status", "loading…");
  try {
    const {query, words} = await windowQuery();
    const picked = $("measurement").value;
    const population = $("population").value;
    const subgroup = Math.max(2, Math.min(10, Number($("subgroup").value) || 5));
    const report = await getJson("/api/stats?" + queryString({...query, population}));
    fillPicker(report.recipes || []);
    renderCapability(report, picked);
    const base = `/api/charts/${encodeURIComponent(picked)}.svg?`;
    await Promise.all([
      showChart($("chart-imr"), base + queryString({...query, population, chart: "imr"})),
      showChart($("chart-xbar"), base + queryString({...query, population, chart: "xbar_r", subgroup})),
      showChart($("chart-hist"), base + queryString({...query, population, chart: "histogram"})),
    ]);
    yieldWindow = query;
    await showYield();
    status("window-status", `${picked}: ${words}`);
  } catch (e) {
    status("window-status", e.message, true);
  }
}

// --- Yield over the same window (GET /api/yield, station/reports/yield.h defines each figure). ---

let yieldWindow = {};  // the window of the last refresh

function pct(v) {
  return v === null || v === undefined ? "—" : (100 * v).toFixed(1) + " %";
}

function yieldRow(g, isTotal) {
  const row = el("tr", {"data-key": g.key, class: isTotal ? "total" : "group"});
  const top = (g.pareto || []).slice(0, 3).map(p => `${p.code} ${p.tests}`).join(", ");
  for (const v of [isTotal ? "total" : g.key, g.units, pct(g.first_pass_yield), pct(g.first_verdict_yield),
                   pct(g.final_yield), g.final_fail, g.final_open, g.retested_units,
                   g.tests_per_unit === null ? "—" : g.tests_per_unit.toFixed(2), g.tests, top || "—"])
    row.appendChild(el("td", {}, String(v)));
  row.addEventListener("click", () => showPareto(g, isTotal));
  return row;
}

function renderYield(report) {
  const t = $("yield");
  t.replaceChildren();
  const head = el("tr");
  for (const h of ["group", "units", "first pass", "first verdict", "final", "FAIL", "open", "retested",
                   "tests per unit", "tests", "top reasons (tests)"])
    head.appendChild(el("th", {scope: "col"}, h));
  t.appendChild(head);
  for (const g of report.groups || []) t.appendChild(yieldRow(g, false));
  t.appendChild(yieldRow(report.total, true));
  const w = report.window || {};
  $("yield-note").textContent = `(production units; ${w.time_zone || ""}; first pass: the first test PASSed, ` +
      "an ERROR first is not; first verdict: the first PASS/FAIL was PASS; open: the last test was ERROR or " +
      "ABORTED; click a row for its Pareto)";
}

// The Pareto of one group (or the total); none is asked for a group without a non-PASS test.
async function showPareto(g, isTotal) {
  const img = $("chart-pareto"), caption = img.parentElement.querySelector("figcaption");
  caption.dataset.base = caption.dataset.base || caption.textContent;
  if (!(g.pareto || []).length) {
    img.hidden = true;
    img.removeAttribute("src");
    caption.textContent = `${caption.dataset.base}: no non-PASS test in ${isTotal ? "the window" : g.key}`;
    return;
  }
  const by = $("yield-by").value;
  await showChart(img, "/api/yield/pareto.svg?" +
                  queryString({...yieldWindow, by, shifts: $("yield-shifts").value, group: isTotal ? "all" : g.key}));
}

async function showYield() {
  status("yield-status", "loading…");
  try {
    const by = $("yield-by").value;
    const report = await getJson("/api/yield?" + queryString({...yieldWindow, by, shifts: $("yield-shifts").value}));
    renderYield(report);
    await showPareto(report.total, true);
    status("yield-status", `${report.total.units} units, ${report.total.tests} tests`);
  } catch (e) {
    status("yield-status", e.message, true);
  }
}

// --- Detectability with the recipe in use. ---

async function detectability() {
  const k = $("k-fixture").value;
  const t = $("detectability");
  try {
    const res = await fetch("/api/detectability" + (k ? "?k_fixture=" + encodeURIComponent(k) : ""),
                            {cache: "no-store"});
    const d = await res.json();
    if (!res.ok && !d.classes) throw new Error(d.error ? d.error.message : d.message || "HTTP " + res.status);
    t.replaceChildren();
    const head = el("tr");
    for (const h of ["defect class", "f0 (Hz)", "Q", "best measurement", "separation (sigma)", "detectable",
                     "remedies"])
      head.appendChild(el("th", {scope: "col"}, h));
    t.appendChild(head);
    for (const c of d.classes || []) {
      const row = el("tr", {"data-defect": c.defect, class: c.separable ? "separable" : "hidden-defect"});
      for (const v of [c.defect, num(c.f0_hz, 4), num(c.q, 3), c.best || "—", num(c.best_separation, 3),
                       c.separable ? "yes" : "no", (c.remedies || []).join("; ")])
        row.appendChild(el("td", {}, String(v)));
      t.appendChild(row);
    }
    $("detect-note").textContent = `(fixture ${num(d.k_fixture_nm_per_rad, 4)} N m/rad from ${d.k_fixture_source}; ` +
        `good unit f0 ${num(d.f0_good_hz, 4)} Hz)`;
  } catch (e) {
    t.replaceChildren();
    $("detect-note").textContent = "(" + e.message + ")";
  }
}

// --- POD and gap figures from the engineer's files. ---

// POSTs JSON with the engineer's token when one is typed; on 401/403 asks for it. Shows the
// answer's SVG in `img`, or the API's reason in the status line.
async function drawFigure(url, body, img, statusId) {
  status(statusId, "drawing…");
  const headers = {"Content-Type": "application/json"};
  const token = $("token").value;
  if (token) headers.Authorization = "Bearer " + token;
  let res;
  try {
    res = await fetch(url, {method: "POST", headers, body: JSON.stringify(body)});
  } catch (e) {
    status(statusId, "station not reachable (" + e.message + ")", true);
    return;
  }
  if (!res.ok) {
    if (res.status === 401 || res.status === 403) $("token-row").hidden = false;
    img.hidden = true;
    status(statusId, await failure(res), true);
    return;
  }
  if (img.src.startsWith("blob:")) URL.revokeObjectURL(img.src);
  img.src = URL.createObjectURL(await res.blob());
  img.hidden = false;
  status(statusId, "drawn");
}

async function drawPod(e) {
  e.preventDefault();
  const file = $("pod-hits").files[0];
  if (!file) return status("pod-status", "choose a hits CSV", true);
  const body = {hits_csv: await file.text(), name: file.name, link: $("pod-link").value};
  const limits = $("pod-limits").value.split(",").map(s => s.trim()).filter(Boolean);
  if (limits.some(v => !isFinite(Number(v)))) return status("pod-status", "f0 limits must be numbers", true);
  if (limits.length) body.f0_limits_hz = limits.map(Number);
  await drawFigure("/api/pod.svg", body, $("pod-figure"), "pod-status");
}

async function drawGap(e) {
  e.preventDefault();
  const sim = $("gap-sim").files[0], measured = [...$("gap-measured").files];
  if (!sim || !measured.length) return status("gap-status", "choose a simulation and measured units", true);
  const upload = async f => ({name: f.name, text: await f.text()});
  const body = {simulation: await upload(sim), measured: await Promise.all(measured.map(upload)),
                quantity: $("gap-quantity").value};
  await drawFigure("/api/gap.svg", body, $("gap-figure"), "gap-status");
}

async function main() {
  try {
    const recipe = await getJson("/api/recipe");
    $("recipe").textContent = `recipe ${recipe.id} v${recipe.version}`;
  } catch (e) {
    $("recipe").textContent = "recipe unavailable";
  }
  $("token").value = sessionStorage.getItem("eol.engineer_token") || "";
  $("token-row").hidden = !$("token").value;
  $("token").addEventListener("change", () => sessionStorage.setItem("eol.engineer_token", $("token").value));
  $("window-form").addEventListener("submit", e => { e.preventDefault(); refresh(); });
  $("measurement").addEventListener("change", refresh);
  $("yield-form").addEventListener("submit", e => { e.preventDefault(); showYield(); });
  $("detect-form").addEventListener("submit", e => { e.preventDefault(); detectability(); });
  $("pod-form").addEventListener("submit", drawPod);
  $("gap-form").addEventListener("submit", drawGap);
  await Promise.all([refresh(), detectability()]);
  document.body.dataset.ready = "true";
}

main();
