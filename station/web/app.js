// Operator display: a serial field for a keyboard-wedge scanner that starts tests over the
// API, live state over server-sent events, the verdict with the recipe's instruction above
// its technical reasons, the measured curve against every limit the verdict used, and the
// last results. No libraries, no network beyond this station.
"use strict";

const STATES = ["wait_serial", "check_interlocks", "clamp", "confirm_clamp", "excite",
                "analyse", "judge", "unclamp", "store", "publish", "confirm_release"];
const FINAL = ["PASS", "FAIL", "ERROR", "ABORTED"];
let recipe = null;
let shownTestId = null;

// --- Words: every text the page shows comes from the catalogue of its language
// (station/web/i18n/<lang>.json, README there): the station's ("language" in /api/status, from
// the station config), or the engineer's choice in the address (?lang=de). English is loaded
// too: a key missing from the chosen catalogue shows in English and is named in
// body[data-missing-words] (the browser tests fail on it); a raw key is never shown.
const LANGUAGES = ["en", "de", "ja"];
let WORDS = {}, ENGLISH = {};
const missingWords = new Set();

function t(key, vars) {
  let text = WORDS[key];
  if (typeof text !== "string") {
    missingWords.add(key);
    document.body.dataset.missingWords = [...missingWords].join(" ");
    text = typeof ENGLISH[key] === "string" ? ENGLISH[key] : key;
  }
  return text.replace(/\{([a-z0-9_]+)\}/g, (m, name) => (vars && name in vars ? String(vars[name]) : m));
}

async function loadWords() {
  const asked = new URLSearchParams(location.search).get("lang");
  let lang = LANGUAGES.includes(asked) ? asked : null;
  if (!lang) lang = await getJson("/api/status").then(s => s.language, () => "en");
  if (!LANGUAGES.includes(lang)) lang = "en";
  ENGLISH = await getJson("/static/i18n/en.json").catch(() => ({}));
  WORDS = lang === "en" ? ENGLISH : await getJson(`/static/i18n/${lang}.json`).catch(() => ({}));
  document.documentElement.lang = lang;
  document.body.dataset.lang = lang;
  document.title = t("ui.title");
  for (const e of document.querySelectorAll("[data-i18n]")) e.textContent = t(e.dataset.i18n);
  for (const e of document.querySelectorAll("[data-i18n-aria]")) e.setAttribute("aria-label", t(e.dataset.i18nAria));
  for (const e of document.querySelectorAll("[data-i18n-placeholder]")) e.placeholder = t(e.dataset.i18nPlaceholder);
}

// The measurements' units and digits (analysis/qc/measurement_names.h); their names are the
// catalogue's "measurement.<name>". scale converts the recorded unit into the one shown; digits
// are significant digits.
const MEASUREMENTS = {
  resonance_f_hz: {unit: "Hz", digits: 4, fixed: true},
  resonance_q: {unit: "", digits: 3, fixed: true},
  winding_r_ohm: {unit: "Ω", digits: 3, fixed: true},
  winding_l_h: {unit: "mH", scale: 1e3, digits: 3, fixed: true},
  motional_rp_ohm: {unit: "Ω", digits: 3, fixed: true},
  fit_chi2_per_dof: {unit: "", digits: 2, fixed: true},
  motional_residue_ohm_per_s: {unit: "Ω/s", digits: 4, fixed: true},
  bond_index_pct: {unit: "%", digits: 3},
  second_mode_chi2_drop: {unit: "", digits: 3},
  resonance_f_ref_pressure_hz: {unit: "Hz", digits: 4, fixed: true},
};

// How a recorded measurement is shown: {label, unit, scale, digits, fixed}. Names of further phase
// pairs end in "@V-W"; a mask's count is "mask_<name>_lines_outside".
function describe(m) {
  const [base, pair] = m.name.split("@");
  let d = MEASUREMENTS[base] && {...MEASUREMENTS[base], label: t("measurement." + base)};
  const mask = /^mask_(.+)_lines_outside$/.exec(base);
  if (!d && mask) d = {label: t("measurement.mask", {name: mask[1].replaceAll("_", " ")}), unit: "", digits: 6};
  if (!d) d = {label: base, unit: m.unit === "1" ? "" : m.unit, digits: 5};
  return {scale: 1, ...d, label: d.label + (pair ? " " + t("ui.phase_pair", {pair}) : "")};
}

function $(id) { return document.getElementById(id); }

function el(tag, attrs, text) {
  const ns = ["svg", "path", "line", "text", "rect", "polygon", "g"].includes(tag)
      ? "http://www.w3.org/2000/svg" : null;
  const e = ns ? document.createElementNS(ns, tag) : document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  if (text !== undefined) e.textContent = text;
  return e;
}

async function getJson(url) {
  const r = await fetch(url, {cache: "no-store"});
  if (!r.ok) throw new Error(url + ": HTTP " + r.status);
  return r.json();
}

// A number to at most `digits` significant digits; `fixed`: exactly that many ("2.00").
function num(v, digits, fixed) {
  if (v === null || v === undefined || !isFinite(v)) return "—";
  const d = digits || 5;
  return new Intl.NumberFormat(undefined, {maximumSignificantDigits: d, useGrouping: false,
                                          minimumSignificantDigits: fixed ? d : 1}).format(v);
}

function withUnit(text, unit) { return unit ? text + " " + unit : text; }

// Times are stored in UTC; the operator reads them in the station's local time, with its zone.
const TIME = new Intl.DateTimeFormat(undefined, {hour: "2-digit", minute: "2-digit", second: "2-digit",
                                                 timeZoneName: "short"});
const DATE_TIME = new Intl.DateTimeFormat(undefined, {year: "numeric", month: "short", day: "numeric",
                                                      hour: "2-digit", minute: "2-digit",
                                                      second: "2-digit", timeZoneName: "short"});
function localTime(iso, format) {
  const t = iso ? new Date(iso) : null;
  return t && !isNaN(t) ? (format || TIME).format(t) : "";
}

function renderStates(current) {
  const ol = $("states");
  ol.replaceChildren();
  const idx = STATES.indexOf(current);
  STATES.forEach((s, i) => {
    const cls = s === current ? "current" : (idx >= 0 && i < idx ? "done" : "");
    ol.appendChild(el("li", {class: cls, "data-state": s}, t("state." + s)));
  });
  if (current === "safe_state") ol.appendChild(el("li", {class: "current"}, t("state.safe_state")));
}

// A reason is {code, text, cause?} (analysis/qc/measurement.h); a plain string is one stored
// before reasons had codes. Its operator words are the catalogue's "what.<key>" and "do.<key>",
// the key being its cause (station/daemon/reason_cause.h) where it has one, else its code.
function asReason(r) {
  return typeof r === "string" ? {code: "legacy", text: r} : {code: "legacy", text: "", ...r};
}
function reasonKey(r) {
  return r.cause && typeof ENGLISH["do." + r.cause] === "string" ? r.cause : r.code;
}

// Causes that leave the rotor clamped or live: their instruction goes first, whatever came before.
const DO_NOT_TOUCH = ["fixture.clamp_left_closed", "fixture.excitation_off_unconfirmed",
                      "fixture.clamp_not_released"];

// The recipe's defaults (station/daemon/recipe.h OperatorInstructions): the page shows the catalogue's
// instruction per cause instead, and the recipe's own only where the plant changed it.
const RECIPE_DEFAULTS = {fail: "Put the rotor in the red reject bin",
                         error: "Test the rotor again; if ERROR repeats, call maintenance",
                         aborted: "Test the rotor again"};

// What the operator does after FAIL, ERROR or ABORTED: the catalogue's instruction for the
// reason that matters most, and the recipe's instruction for the outcome where the plant wrote
// its own (e.g. which bin); none for PASS.
function instructionFor(outcome, reasons) {
  if (!FINAL.includes(outcome) || outcome === "PASS") return {text: "", note: ""};
  const all = (reasons || []).map(asReason);
  const first = all.find(r => DO_NOT_TOUCH.includes(r.cause)) || all[0];
  const text = first ? t("do." + reasonKey(first)) : t("do." + (outcome === "FAIL" ? "limit" : outcome === "ABORTED" ? "aborted" : "internal"));
  const own = recipe && recipe.instructions && recipe.instructions[outcome.toLowerCase()];
  const note = own && own !== RECIPE_DEFAULTS[outcome.toLowerCase()] ? t("ui.plant_note", {text: own}) : "";
  return {text, note, cause: first ? reasonKey(first) : ""};
}

// outcome: PASS, FAIL, ERROR, ABORTED, RUNNING (shown as TESTING) or none. A master part's
// self-check (kind "self_check") gets no production instruction: it goes back to the masters.
function renderOutcome(outcome, serial, reasons, kind) {
  const v = $("verdict");
  v.className = "verdict " + (outcome || "none");
  v.textContent = outcome ? t("outcome." + outcome) : "—";
  $("serial").textContent = serial || "";
  const master = kind === "self_check";
  const instruction = master ? {text: t("ui.master_instruction"), note: ""} : instructionFor(outcome, reasons);
  const box = $("instruction");
  box.hidden = !instruction.text;
  box.className = master ? "MASTER" : outcome || "";
  box.dataset.key = master ? "" : instruction.cause || "";
  box.replaceChildren(instruction.text);
  if (instruction.note) box.append(el("span", {class: "note"}, instruction.note));
  const ul = $("reasons");
  ul.replaceChildren();
  for (const r of (reasons || []).map(asReason)) {
    const li = el("li", {"data-code": r.code, "data-cause": r.cause || ""});
    li.append(el("span", {class: "what"}, t("what." + reasonKey(r))), " ", el("span", {class: "why"}, r.text));
    ul.appendChild(li);
  }
  if (outcome === "RUNNING") $("tested").textContent = "";
}

function renderTested(record) {
  const who = [];
  if (record.operator_id) who.push(t("ui.tested_operator", {id: record.operator_id}));
  if (record.shift) who.push(t("ui.tested_shift", {shift: record.shift}));
  if (record.order_number) who.push(t("ui.tested_order", {order: record.order_number}));
  const when = localTime(record.finished_at, DATE_TIME);
  $("tested").textContent = (when ? t("ui.finished", {when}) : "") + (who.length ? " · " + who.join(" · ") : "");
}

function renderHistory(status) {
  const table = $("history");
  table.replaceChildren(el("tr", {}, ""));
  table.firstChild.append(...["serial", "outcome", "resonance", "finished"].map(c => el("th", {scope: "col"}, t("ui.col_" + c))));
  for (const r of status.recent || []) {
    const f0 = (r.measurements || []).find(m => m.name === "resonance_f_hz");
    const row = el("tr");
    row.append(el("td", {}, r.serial), el("td", {class: r.outcome, "data-outcome": r.outcome}, t("outcome." + r.outcome)),
               el("td", {}, num(f0 && f0.value, 4, true)),
               el("td", {"data-utc": r.finished_at || r.started_at || ""},
                  localTime(r.finished_at || r.started_at)));
    table.appendChild(row);
  }
  const c = status.counts || {};
  $("counts").textContent = (c.day ? t("ui.counts_today") + " " : "") +
      FINAL.map(o => `${t("outcome." + o)} ${c[o.toLowerCase()] || 0}`).join(" · ");
}

// The failing measurements first (they must be visible at 1280x800 without scrolling), then
// the others in the record's order.
function renderMeasurements(measurements) {
  const table = $("measurements");
  table.replaceChildren();
  const head = el("tr");
  head.append(...["measurement", "value", "limits", "result"].map(c => el("th", {scope: "col"}, t("ui.col_" + c))));
  table.appendChild(head);
  const all = measurements || [];
  for (const m of [...all.filter(x => x.outcome === "FAIL"), ...all.filter(x => x.outcome !== "FAIL")]) {
    const d = describe(m);
    const scaled = v => (v === null || v === undefined) ? null : v * d.scale;
    const lo = m.limit.lo ?? null, hi = m.limit.hi ?? null;
    const limits = lo !== null && hi !== null ? `${num(scaled(lo), 6)} … ${num(scaled(hi), 6)}`
        : lo !== null ? "≥ " + num(scaled(lo), 6) : hi !== null ? "≤ " + num(scaled(hi), 6) : t("ui.limits_none");
    const result = m.outcome === "PASS" || m.outcome === "FAIL" ? t("outcome." + m.outcome) : t("ui.not_judged");
    const row = el("tr", {"data-name": m.name});
    row.append(el("td", {title: m.name + (m.doc ? ": " + m.doc : "")}, d.label),
               el("td", {class: "value"}, withUnit(num(scaled(m.value), d.digits, d.fixed), d.unit)),
               el("td", {}, withUnit(limits, d.unit)),
               el("td", {class: m.outcome === "PASS" || m.outcome === "FAIL" ? m.outcome : "UNSET"},
                  result + (m.marginal ? " " + t("ui.marginal") : "")));
    table.appendChild(row);
  }
}

// Interpolates a mask bound ("lo" or "hi") at f; null where the mask does not bound.
function maskAt(points, key, f) {
  for (let i = 0; i + 1 < points.length; i++) {
    const a = points[i], b = points[i + 1];
    if (f >= a.f_hz && f <= b.f_hz && a[key] != null && b[key] != null)
      return a[key] + (b[key] - a[key]) * (f - a.f_hz) / (b.f_hz - a.f_hz);
  }
  return null;
}

// A legend key: [kind, text] or [kind, text, pair index]; the pair picks the swatch colour.
function renderLegend(keys) {
  $("legend").replaceChildren(...keys.map(([cls, text, pair]) =>
      el("span", pair === undefined ? {class: "key " + cls} : {class: "key " + cls, "data-pair": pair}, text)));
}

const PLOTS = ["plot", "plot-abs"];

function clearPlot(note) {
  for (const id of PLOTS) {
    $(id).replaceChildren();
    $(id).removeAttribute("data-serial");
    $(id).setAttribute("aria-label", t("ui.no_curve") + (note ? ": " + note : ""));
  }
  $("plot-abs").toggleAttribute("hidden", true);  // an SVG element has no .hidden property
  $("curve-note").textContent = note ? "(" + note + ")" : "";
  renderLegend([]);
}

// The recorder's phase-pair names (station/daemon/judge.cc PairName), by conditions.phase_pair.
const PAIR_NAMES = ["U-V", "V-W", "W-U"];

// Every phase pair the record measured, the recipe's first pair first: its curves are
// "impedance" and "model", a further pair's "impedance@V-W" and "model@V-W", and so are its
// measurements ("resonance_f_hz@V-W").
function measuredPairs(record) {
  const curves = record.curves || [];
  const first = PAIR_NAMES[(record.conditions || {}).phase_pair] || t("ui.first_pair");
  const pairs = [];
  for (const c of curves) {
    const m = /^impedance(?:@(.+))?$/.exec(c.name);
    if (!m) continue;
    const suffix = m[1] ? "@" + m[1] : "";
    const resonance = (record.measurements || []).find(x => x.name === "resonance_f_hz" + suffix);
    pairs.push({name: m[1] || first, measured: c, model: curves.find(x => x.name === "model" + suffix),
                f0: resonance && isFinite(resonance.value) ? resonance.value : null});
  }
  return pairs;
}

// What a mask bounds (analysis/qc/curve_mask.h MaskQuantity), from a curve's Re and Im in ohm.
const QUANTITIES = {
  re_ohm: {label: "Re Z", value: (c, i) => c.re[i]},
  abs_ohm: {label: "|Z|", value: (c, i) => Math.hypot(c.re[i], c.im[i])},
};

// One panel: the resonance window, the masks on this quantity, each pair's measured curve and
// resonance, and each pair's fitted model last (on top, never hidden under a measured curve).
// Returns the number of mask areas drawn.
function drawPanel(svg, pairs, quantity, masks, win) {
  svg.replaceChildren();
  const q = QUANTITIES[quantity];
  const [, , W, H] = svg.getAttribute("viewBox").split(" ").map(Number);
  const L = 60, R = 15, T = 15, B = 40;
  const freqs = pairs.flatMap(p => [p.measured.freq_hz[0], p.measured.freq_hz[p.measured.freq_hz.length - 1]]);
  const f0 = Math.min(...freqs), f1 = Math.max(...freqs);
  const values = c => c.freq_hz.map((_, i) => q.value(c, i));
  let ys = [];
  for (const p of pairs) {
    p[quantity] = {measured: values(p.measured), model: p.model ? values(p.model) : null};
    ys = ys.concat(p[quantity].measured.filter(isFinite), (p[quantity].model || []).filter(isFinite));
  }
  for (const m of masks) for (const p of m.points) for (const k of ["lo", "hi"]) if (p[k] != null) ys.push(p[k]);
  let y0 = Math.min(...ys), y1 = Math.max(...ys);
  const pad = 0.08 * (y1 - y0 || 1);
  y0 -= pad; y1 += pad;
  const X = f => L + (Math.min(Math.max(f, f0), f1) - f0) / (f1 - f0) * (W - L - R);
  const Y = y => T + (y1 - y) / (y1 - y0) * (H - T - B);
  if (win && (win.lo != null || win.hi != null)) {
    const lo = win.lo ?? f0, hi = win.hi ?? f1;
    svg.appendChild(el("rect", {class: "window", x: X(lo), width: X(hi) - X(lo), y: T, height: H - T - B,
                                "data-lo": lo, "data-hi": hi}));
  }
  const rows = H > 300 ? 6 : 4;
  for (let i = 0; i <= 6; i++) {
    const f = f0 + i * (f1 - f0) / 6;
    svg.append(el("line", {class: "grid", x1: X(f), x2: X(f), y1: T, y2: H - B}),
               el("text", {x: X(f) - 15, y: H - B + 18}, f.toFixed(0)));
  }
  for (let i = 0; i <= rows; i++) {
    const y = y0 + i * (y1 - y0) / rows;
    svg.append(el("line", {class: "grid", x1: L, x2: W - R, y1: Y(y), y2: Y(y)}),
               el("text", {x: 5, y: Y(y) + 4}, y.toFixed(2)));
  }
  svg.append(el("text", {x: W / 2 - 30, y: H - 5}, "f (Hz)"),
             el("text", {class: "quantity", x: L + 8, y: T + 16}, q.label + " (Ω)"));
  let maskCount = 0;
  for (const m of masks) {
    for (const key of ["lo", "hi"]) {
      const pts = [];
      const a = Math.max(f0, m.points[0].f_hz), b = Math.min(f1, m.points[m.points.length - 1].f_hz);
      for (let i = 0; i <= 200 && b > a; i++) {
        const f = a + i * (b - a) / 200;
        const v = maskAt(m.points, key, f);
        if (v != null) pts.push([X(f), Y(v)]);
      }
      if (pts.length < 2) continue;
      const edge = key === "hi" ? T : H - B;
      const poly = pts.map(p => p.join(",")).concat([`${pts[pts.length - 1][0]},${edge}`, `${pts[0][0]},${edge}`]);
      svg.appendChild(el("polygon", {class: "mask", points: poly.join(" "), "data-mask": m.name,
                                     "data-bound": key}));
      ++maskCount;
    }
  }
  const line = (c, y, cls, k, name) => {
    const d = c.freq_hz.map((f, i) => (i ? "L" : "M") + X(f).toFixed(1) + "," + Y(y[i]).toFixed(1)).join("");
    svg.appendChild(el("path", {class: cls, d, "data-points": c.freq_hz.length, "data-pair": k,
                                "data-pair-name": name}));
  };
  pairs.forEach((p, k) => line(p.measured, p[quantity].measured, "measured", k, p.name));
  pairs.forEach((p, k) => {
    if (p.f0 !== null)
      svg.appendChild(el("line", {class: "f0", x1: X(p.f0), x2: X(p.f0), y1: T, y2: H - B, "data-pair": k}));
  });
  pairs.forEach((p, k) => { if (p.model) line(p.model, p[quantity].model, "model", k, p.name); });
  return maskCount;
}

// Re Z, and |Z| below it when the recipe bounds |Z|: every phase pair's measured curve and
// fitted model against every limit the verdict used (the resonance window from the record's own
// limit, the recipe's masks on each quantity).
function plotCurves(record) {
  const pairs = measuredPairs(record);
  if (!pairs.length) {
    clearPlot("no curve: " + reasonText((record.reasons || [""])[0]));
    return;
  }
  const masks = (recipe && recipe.masks) || [];
  const reMasks = masks.filter(m => (m.quantity || "re_ohm") === "re_ohm");
  const absMasks = masks.filter(m => m.quantity === "abs_ohm");
  const sameRecipe = recipe && record.recipe && recipe.hash === record.recipe.hash;
  const resonance = (record.measurements || []).find(m => m.name === "resonance_f_hz");
  const win = resonance && resonance.limit;
  const several = pairs.length > 1;
  const pairText = p => (several ? " " + p.name : "");
  const keys = pairs.map((p, k) => ["measured", t("ui.legend_measured") + pairText(p), k]);
  pairs.forEach((p, k) => { if (p.model) keys.push(["model", t("ui.legend_model") + pairText(p), k]); });
  if (win && (win.lo != null || win.hi != null)) {
    const range = win.lo == null ? "≤ " + num(win.hi, 6) : win.hi == null ? "≥ " + num(win.lo, 6)
        : num(win.lo, 6) + "–" + num(win.hi, 6);
    keys.push(["window", t("ui.legend_window", {range})]);
  }
  const note = sameRecipe ? "" : " " + t("ui.legend_recipe_in_use");
  if (drawPanel($("plot"), pairs, "re_ohm", reMasks, win))
    keys.push(["mask", t("ui.legend_mask_re") + note]);
  $("plot-abs").toggleAttribute("hidden", absMasks.length === 0);
  if (!absMasks.length) $("plot-abs").replaceChildren();
  else if (drawPanel($("plot-abs"), pairs, "abs_ohm", absMasks, win))
    keys.push(["mask", t("ui.legend_mask_abs") + note]);
  pairs.forEach((p, k) => {
    if (p.f0 !== null) keys.push(["f0", t("ui.legend_f0", {f0: num(p.f0, 4, true)}) + pairText(p), k]);
  });
  renderLegend(keys);
  $("curve-note").textContent = "— " + record.serial +
      (several ? ", " + t("ui.phase_pairs", {pairs: pairs.map(p => p.name).join(", ")}) : "");
  for (const [id, q] of [["plot", "Re Z"], ["plot-abs", "|Z|"]]) {
    $(id).setAttribute("data-serial", record.serial);
    $(id).setAttribute("aria-label", t("ui.curve_label", {quantity: q, serial: record.serial, keys: keys.map(k => k[1]).join(", ")}));
  }
}

async function showTest(id) {
  if (id === null || id === undefined || id === shownTestId) return;
  shownTestId = id;
  try {
    const record = await getJson("/api/tests/" + id);
    if (id !== shownTestId) return;  // a newer test is shown meanwhile
    plotCurves(record);
    renderMeasurements(record.measurements);
    renderTested(record);
  } catch (e) {
    clearPlot(e.message);
  }
}

// Retest marking (GET /api/status "last".attempt, max_tests): "retest 2 of 3" for a serial's
// second test of the three its recipe allows, nothing for a first test or an unstored refusal.
function renderAttempt(summary) {
  const a = (summary && summary.attempt) || 0, of = (summary && summary.max_tests) || 0;
  $("attempt").textContent = a > 1 ? `retest ${a}` + (of ? ` of ${of}` : "") +
      (of && a >= of ? " (last allowed test)" : "") : "";
}

// A finished result: its record when it was stored (id > 0); a refusal before anything moved
// (lockout, retest limit) is not stored and has no curve.
function showResult(summary) {
  renderOutcome(summary.outcome, summary.serial, summary.reasons, summary.kind);
  renderAttempt(summary);
  if (summary.id > 0) {
    showTest(summary.id);
  } else {
    shownTestId = null;
    clearPlot(t("ui.not_stored"));
    renderMeasurements([]);
    $("tested").textContent = t("ui.refused", {when: localTime(summary.finished_at || summary.started_at, DATE_TIME)});
  }
}

function showRunning(serial) {
  renderOutcome("RUNNING", serial, []);
  renderAttempt(null);
  shownTestId = null;  // the last unit's curve is not this one's
  clearPlot(t("ui.test_running"));
  renderMeasurements([]);
}

// Self-check lockout: production tests are refused until the master parts pass.
function renderLockout(lockout) {
  const b = $("lockout");
  b.hidden = !(lockout && lockout.locked);
  b.textContent = b.hidden ? "" : t("ui.lockout", {reason: lockout.reason});
  document.body.classList.toggle("locked", !b.hidden);
}

// A station on simulators or recorded data: nothing it shows is a production result.
function renderSimulation(why) {
  const b = $("simulation");
  b.hidden = !why;
  b.textContent = why ? t("ui.simulation", {why}) : "";
}

// Readiness (station/daemon/health.h): what the operator does in large type, the technical reason
// under it, the cause's code in data-code. `r` is /api/status or a "readiness" event.
function renderReadiness(r) {
  const b = $("not-ready");
  b.hidden = r.ready !== false;
  b.dataset.code = b.hidden ? "" : r.not_ready_code || "";
  if (b.hidden) {
    b.replaceChildren();
    return;
  }
  const words = r.not_ready_code && typeof ENGLISH["not_ready." + r.not_ready_code] === "string"
      ? t("not_ready." + r.not_ready_code) : r.not_ready_text || r.not_ready_reason;
  b.replaceChildren(el("span", {class: "what"}, t("ui.not_ready", {text: words})),
                    el("span", {class: "why"}, r.not_ready_reason || ""));
}

// --- The link to the station: offline within 2 s of losing it. ---
// The event stream sends something at least every 0.5 s (a "ping" when nothing happens);
// nothing for OFFLINE_AFTER_MS, or the stream failing, is a lost station: the verdict is
// greyed (it may be old) and Start is disabled until the stream is back.
const OFFLINE_AFTER_MS = 1500;
let lastHeard = 0, offline = true;

function setOffline(now) {
  if (now === offline) return;
  offline = now;
  const c = $("connection");
  c.textContent = now ? t("ui.offline") : t("ui.live");
  c.className = now ? "offline" : "online";
  document.body.classList.toggle("offline", now);
  $("offline").hidden = !now;
  $("start").disabled = now;
  if (!now) refreshStatus().catch(() => {});  // what happened while the link was down
}

function heard() {
  lastHeard = performance.now();
  setOffline(false);
}

function watchLink() {
  setInterval(() => { if (performance.now() - lastHeard > OFFLINE_AFTER_MS) setOffline(true); }, 250);
}

// Events of each kind received over the stream. A status fetched while an event of a kind
// arrived may be older than that event (the lockout lifted while /api/status was answered):
// the event wins, and of overlapping fetches only the newest answer is shown.
const eventsSeen = {};
let statusAsked = 0, statusShown = 0;

async function refreshStatus() {
  const asked = ++statusAsked;
  const before = {...eventsSeen};
  const s = await getJson("/api/status");
  if (asked < statusShown) return;
  statusShown = asked;
  const fresh = (...kinds) => kinds.every(k => (eventsSeen[k] || 0) === (before[k] || 0));
  if (fresh("lockout")) renderLockout(s.lockout);
  renderSimulation(s.simulation);
  if (fresh("readiness")) renderReadiness(s);
  $("station").textContent = t("ui.station", {id: s.station_id});
  if (fresh("message")) $("message").textContent = s.message || "";
  renderHistory(s);
  if (!fresh("state", "verdict")) return;
  const running = s.state !== "wait_serial" && s.state !== "idle" && s.state !== "publish";
  if (running) {
    if ($("serial").textContent !== s.serial || !$("verdict").classList.contains("RUNNING")) showRunning(s.serial);
  } else if (s.last) {
    showResult(s.last);
  }
  renderStates(s.state);
}

async function loadRecipe() {
  try {
    recipe = await getJson("/api/recipe");
    $("recipe").textContent = t("ui.recipe", {id: recipe.id, version: recipe.version});
  } catch (e) {
    $("recipe").textContent = t("ui.recipe_unavailable");
  }
}

// --- Starting tests: a keyboard-wedge scanner types the serial and Enter into #scan. ---

// The serial field keeps the focus: whenever nothing else that takes text has it, the next
// keystroke (the scanner's) lands there.
function keepScanFocus() {
  const scan = $("scan");
  const takesText = e => e && ["INPUT", "TEXTAREA", "SELECT", "BUTTON"].includes(e.tagName);
  const refocus = () => { if (!takesText(document.activeElement)) scan.focus(); };
  scan.addEventListener("blur", () => setTimeout(refocus, 0));  // the new focus is known after blur
  document.addEventListener("click", refocus);
  document.addEventListener("keydown", e => {
    if (!takesText(document.activeElement) && !e.ctrlKey && !e.altKey && !e.metaKey) scan.focus();
  });
  // Operator and shift: Enter there stores them and hands the focus back to the scanner.
  for (const id of ["operator-id", "shift", "token"]) {
    $(id).addEventListener("keydown", e => {
      if (e.key === "Enter") { e.preventDefault(); saveWork(); scan.focus(); }
    });
    $(id).addEventListener("change", saveWork);
  }
  scan.focus();
}

// Operator and shift are kept in this browser (one browser per station) and go with every
// test the page starts; the token only for this session.
function saveWork() {
  localStorage.setItem("eol.operator_id", $("operator-id").value.trim());
  localStorage.setItem("eol.shift", $("shift").value.trim());
  sessionStorage.setItem("eol.token", $("token").value);
}

function loadWork() {
  $("operator-id").value = localStorage.getItem("eol.operator_id") || "";
  $("shift").value = localStorage.getItem("eol.shift") || "";
  $("token").value = sessionStorage.getItem("eol.token") || "";
  $("token-row").hidden = !$("token").value;
}

// When the shown refusal was made, and when the latest test began (page time, ms): a verdict
// clears only a refusal made before its test began (a serial refused while that test ran must
// still be scanned again).
let problemAt = -1, testBeganAt = -1;

function startStatus(text, problem) {
  const s = $("start-status");
  s.textContent = text;
  s.className = problem ? "problem" : "";
  if (problem) {
    problemAt = performance.now();
    refusalCue();
  }
}

// Tones made in the page (WebAudio: no sound file, nothing loaded): `count` beeps of `hz`,
// each 0.35 s with 0.15 s between them.
function beep(hz, count) {
  try {
    const ctx = beep.ctx || (beep.ctx = new AudioContext());
    for (let i = 0; i < count; i++) {
      const tone = ctx.createOscillator(), gain = ctx.createGain();
      const at = ctx.currentTime + i * 0.5;
      tone.frequency.value = hz;
      gain.gain.value = 0.25;
      tone.connect(gain).connect(ctx.destination);
      tone.start(at);
      tone.stop(at + 0.35);
    }
  } catch (e) {
    // no audio device: the red text stands alone
  }
}

// A short low tone for a scan that did not start a test. Counted in body[data-cues] for the
// tests.
function refusalCue() {
  document.body.dataset.cues = Number(document.body.dataset.cues || 0) + 1;
  beep(330, 1);
}

// The same tone on a new FAIL (twice) or ERROR (three times), so that an operator who looks
// away hears that the unit needs a hand; none for PASS and ABORTED, none for a result shown
// on loading the page. Counted in body[data-verdict-cues] ("FAIL ERROR ...") for the tests.
function verdictCue(outcome) {
  if (outcome !== "FAIL" && outcome !== "ERROR") return;
  const heard = document.body.dataset.verdictCues;
  document.body.dataset.verdictCues = (heard ? heard + " " : "") + outcome;
  beep(330, outcome === "FAIL" ? 2 : 3);
}

// POST /api/tests as any client does: no token while the station has none configured (the
// API then opens operator routes, station/daemon/http/request.h); with tokens, the operator's.
async function startTest(serial) {
  const body = {serial};
  if ($("variant").value) body.variant = $("variant").value;  // else the serial's rule picks
  const operator = $("operator-id").value.trim(), shift = $("shift").value.trim();
  if (operator) body.operator_id = operator;
  if (shift) body.shift = shift;
  const headers = {"Content-Type": "application/json"};
  const token = $("token").value;
  if (token) headers.Authorization = "Bearer " + token;
  let res, answer = {};
  try {
    res = await fetch("/api/tests", {method: "POST", headers, body: JSON.stringify(body)});
    answer = await res.json().catch(() => ({}));
  } catch (e) {
    startStatus(t("ui.unreachable", {why: e.message}), true);
    return;
  }
  if (res.status === 202) {
    startStatus(t("ui.started", {serial}));
    return;
  }
  const why = (answer.error && answer.error.message) || "HTTP " + res.status;
  if (res.status === 401 || res.status === 403) {
    $("token-row").hidden = false;
    startStatus(t("ui.needs_token", {serial, why}), true);
  } else {
    startStatus(t("ui.refused_scan", {serial, why}), true);
  }
}

// Offline, Start is disabled and the form cannot submit: a scanner's Enter is answered here,
// and its serial does not stay in the field to be glued to the next scan.
function refuseScanWhileOffline(e) {
  if (e.key !== "Enter" || !offline) return;
  e.preventDefault();
  const serial = $("scan").value.trim();
  $("scan").value = "";
  if (serial) startStatus(t("ui.refused_offline", {serial}), true);
}

// A station of several motor types (GET /api/variants) lets the operator name the unit's
// type; left at "from the serial", the station's prefix rules pick it (station/daemon/variants.h).
async function loadVariants() {
  const answer = await getJson("/api/variants").catch(() => null);
  const list = (answer && answer.variants) || [];
  for (const v of list) {
    const option = document.createElement("option");
    option.value = v.name;
    option.textContent = v.recipe ? v.name + " (" + v.recipe.id + ")" : v.name;
    $("variant").appendChild(option);
  }
  $("variant-row").hidden = list.length === 0;
}

function setupStart() {
  loadWork();
  loadVariants();
  $("scan").addEventListener("keydown", refuseScanWhileOffline);
  $("start-form").addEventListener("submit", e => {
    e.preventDefault();
    const serial = $("scan").value.trim();
    $("scan").value = "";
    $("scan").focus();
    if (!serial) return;
    saveWork();
    startStatus(t("ui.sent", {serial}));
    startTest(serial);
  });
  keepScanFocus();
}

// What each kind of event does, with its parsed data.
const HANDLERS = {
  ping: () => {},
  state: e => {
    renderStates(e.state);
    if (e.state === "check_interlocks" && e.detail === "") {
      testBeganAt = performance.now();
      showRunning(e.serial);
    }
  },
  verdict: e => {
    // A new verdict: what was said about the station before its test began is old news.
    $("message").textContent = "";
    if ($("start-status").className === "problem" && problemAt < testBeganAt) startStatus("");
    showResult(e.record);
    if (e.record && e.record.kind !== "self_check") verdictCue(e.record.outcome);
    refreshStatus().catch(() => {});
  },
  recipe: () => { loadRecipe(); },
  lockout: e => renderLockout(e.lockout),
  readiness: e => renderReadiness(e),
  message: e => { $("message").textContent = e.message; },
};

// The event stream. The browser reconnects a lost one by itself (every second: the station
// sends "retry: 1000"); one it gave up on (an HTTP error answered) is opened anew.
function openStream() {
  const source = new EventSource("/api/events");
  for (const [kind, handle] of Object.entries(HANDLERS)) {
    source.addEventListener(kind, ev => {
      heard();
      eventsSeen[kind] = (eventsSeen[kind] || 0) + 1;
      handle(JSON.parse(ev.data));
    });
  }
  source.onopen = heard;
  source.onerror = () => {
    setOffline(true);
    if (source.readyState === EventSource.CLOSED) setTimeout(openStream, 1000);
  };
}

async function main() {
  await loadWords();
  setupStart();
  await loadRecipe();
  await refreshStatus().catch(e => { $("message").textContent = e.message; });
  openStream();
  watchLink();
}

main();
