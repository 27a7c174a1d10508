// Operator display: live state over server-sent events, the verdict with its reasons, the
// measured curve against the recipe's limit masks, and the last results. No libraries, no
// network beyond this station.
"use strict";

const STATES = ["wait_serial", "check_interlocks", "clamp", "confirm_clamp", "excite",
                "analyse", "judge", "unclamp", "store", "publish"];
let recipe = null;
let shownTestId = null;

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

function fmt(v, digits) {
  return (v === null || v === undefined || !isFinite(v)) ? "—" : Number(v).toPrecision(digits || 5);
}

function renderStates(current) {
  const ol = $("states");
  ol.replaceChildren();
  const idx = STATES.indexOf(current);
  STATES.forEach((s, i) => {
    const cls = s === current ? "current" : (idx >= 0 && i < idx ? "done" : "");
    ol.appendChild(el("li", {class: cls, "data-state": s}, s.replace("_", " ")));
  });
  if (current === "safe_state") ol.appendChild(el("li", {class: "current"}, "safe state"));
}

// A reason is {code, text} (analysis/qc/measurement.h); the operator reads the text.
function reasonText(r) {
  return typeof r === "string" ? r : (r && r.text) || "";
}

function renderVerdict(outcome, serial, reasons) {
  const v = $("verdict");
  v.className = "verdict " + (outcome || "none");
  v.textContent = outcome === "RUNNING" ? "TESTING" : (outcome || "—");
  $("serial").textContent = serial || "";
  const ul = $("reasons");
  ul.replaceChildren();
  for (const r of reasons || [])
    ul.appendChild(el("li", {"data-code": (r && r.code) || ""}, reasonText(r)));
}

function renderHistory(status) {
  const t = $("history");
  t.replaceChildren(el("tr", {}, ""));
  t.firstChild.append(el("th", {}, "serial"), el("th", {}, "verdict"), el("th", {}, "f0 (Hz)"),
                      el("th", {}, "finished"));
  for (const r of status.recent || []) {
    const f0 = (r.measurements || []).find(m => m.name === "resonance_f_hz");
    const row = el("tr");
    row.append(el("td", {}, r.serial), el("td", {class: r.outcome}, r.outcome),
               el("td", {}, fmt(f0 && f0.value, 5)), el("td", {}, (r.finished_at || "").slice(11, 19)));
    t.appendChild(row);
  }
  const c = status.counts || {};
  $("counts").textContent = `PASS ${c.pass || 0} · FAIL ${c.fail || 0} · ERROR ${c.error || 0}` +
      ` · ABORTED ${c.aborted || 0}`;
}

function renderMeasurements(measurements) {
  const t = $("measurements");
  t.replaceChildren();
  const head = el("tr");
  head.append(el("th", {}, "measurement"), el("th", {}, "value"), el("th", {}, "limits"),
              el("th", {}, ""));
  t.appendChild(head);
  for (const m of measurements || []) {
    const lim = `${m.limit.lo ?? "−∞"} … ${m.limit.hi ?? "+∞"} ${m.unit}`;
    const row = el("tr");
    row.append(el("td", {}, m.name), el("td", {}, fmt(m.value, 6) + " " + m.unit),
               el("td", {}, lim), el("td", {class: m.outcome === "FAIL" ? "FAIL" : "PASS"},
                                     m.outcome + (m.marginal ? " (marginal)" : "")));
    t.appendChild(row);
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

function plotCurves(record) {
  const svg = $("plot");
  svg.replaceChildren();
  const meas = (record.curves || []).find(c => c.name === "impedance");
  const model = (record.curves || []).find(c => c.name === "model");
  if (!meas) {
    $("curve-note").textContent = "(no curve: " + reasonText((record.reasons || [""])[0]) + ")";
    return;
  }
  $("curve-note").textContent = "— " + record.serial;
  const W = 800, H = 420, L = 60, R = 15, T = 15, B = 40;
  const f0 = meas.freq_hz[0], f1 = meas.freq_hz[meas.freq_hz.length - 1];
  const masks = ((recipe && recipe.masks) || []).filter(m => m.quantity === "re_ohm");
  let ys = meas.re.slice();
  if (model) ys = ys.concat(model.re);
  for (const m of masks) for (const p of m.points) for (const k of ["lo", "hi"]) if (p[k] != null) ys.push(p[k]);
  let y0 = Math.min(...ys), y1 = Math.max(...ys);
  const pad = 0.08 * (y1 - y0 || 1);
  y0 -= pad; y1 += pad;
  const X = f => L + (f - f0) / (f1 - f0) * (W - L - R);
  const Y = y => T + (y1 - y) / (y1 - y0) * (H - T - B);
  for (let i = 0; i <= 6; i++) {
    const f = f0 + i * (f1 - f0) / 6, y = y0 + i * (y1 - y0) / 6;
    svg.append(el("line", {class: "grid", x1: X(f), x2: X(f), y1: T, y2: H - B}),
               el("line", {class: "grid", x1: L, x2: W - R, y1: Y(y), y2: Y(y)}),
               el("text", {x: X(f) - 15, y: H - B + 18}, f.toFixed(0)),
               el("text", {x: 5, y: Y(y) + 4}, y.toFixed(2)));
  }
  svg.append(el("text", {x: W / 2 - 30, y: H - 5}, "f (Hz)"));
  for (const m of masks) {
    for (const key of ["lo", "hi"]) {
      const pts = [];
      for (let f = Math.max(f0, m.points[0].f_hz); f <= Math.min(f1, m.points[m.points.length - 1].f_hz); f += (f1 - f0) / 200) {
        const v = maskAt(m.points, key, f);
        if (v != null) pts.push([X(f), Y(v)]);
      }
      if (pts.length < 2) continue;
      const edge = key === "hi" ? T : H - B;
      const poly = pts.map(p => p.join(",")).concat([`${pts[pts.length - 1][0]},${edge}`, `${pts[0][0]},${edge}`]);
      svg.appendChild(el("polygon", {class: "mask", points: poly.join(" ")}));
    }
  }
  const line = (c, cls) => {
    const d = c.freq_hz.map((f, i) => (i ? "L" : "M") + X(f).toFixed(1) + "," + Y(c.re[i]).toFixed(1)).join("");
    svg.appendChild(el("path", {class: cls, d, "data-points": c.freq_hz.length}));
  };
  if (model) line(model, "model");
  line(meas, "measured");
}

async function showTest(id) {
  if (id === null || id === undefined || id === shownTestId) return;
  shownTestId = id;
  try {
    const record = await getJson("/api/tests/" + id);
    plotCurves(record);
    renderMeasurements(record.measurements);
  } catch (e) {
    $("curve-note").textContent = "(" + e.message + ")";
  }
}

// Self-check lockout: production tests are refused until a master check passes.
function renderLockout(lockout) {
  const el = $("lockout");
  el.hidden = !(lockout && lockout.locked);
  el.textContent = el.hidden ? "" : "LOCKED OUT: " + lockout.reason;
}

async function refreshStatus() {
  const s = await getJson("/api/status");
  renderLockout(s.lockout);
  $("station").textContent = "EOL station " + s.station_id;
  $("message").textContent = s.message || "";
  renderHistory(s);
  const running = s.state !== "wait_serial" && s.state !== "idle" && s.state !== "publish";
  if (running) {
    renderVerdict("RUNNING", s.serial, []);
  } else if (s.last) {
    renderVerdict(s.last.outcome, s.last.serial, s.last.reasons);
    showTest(s.last.id);
  }
  renderStates(s.state);
}

async function main() {
  try {
    recipe = await getJson("/api/recipe");
    $("recipe").textContent = `recipe ${recipe.id} v${recipe.version}`;
  } catch (e) {
    $("recipe").textContent = "recipe unavailable";
  }
  await refreshStatus().catch(e => { $("message").textContent = e.message; });
  const events = new EventSource("/api/events");
  events.onopen = () => { $("connection").textContent = "live"; $("connection").className = "online"; };
  events.onerror = () => { $("connection").textContent = "reconnecting…"; $("connection").className = "offline"; };
  events.addEventListener("state", ev => {
    const e = JSON.parse(ev.data);
    renderStates(e.state);
    if (e.state === "check_interlocks") renderVerdict("RUNNING", e.serial, []);
  });
  events.addEventListener("verdict", ev => {
    const e = JSON.parse(ev.data);
    renderVerdict(e.record.outcome, e.record.serial, e.record.reasons);
    showTest(e.record.id);
    refreshStatus().catch(() => {});
  });
  events.addEventListener("lockout", ev => { renderLockout(JSON.parse(ev.data).lockout); });
  events.addEventListener("message", ev => { $("message").textContent = JSON.parse(ev.data).message; });
}

main();
