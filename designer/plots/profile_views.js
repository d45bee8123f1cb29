// ---- formatting ----
function sig(v, n) { return Number(v.toPrecision(n)).toString(); }
function niceTicks(lo, hi, n) {
  const raw = (hi - lo) / n, mag = Math.pow(10, Math.floor(Math.log10(raw))), k = raw / mag;
  const step = (k < 1.5 ? 1 : k < 3 ? 2 : k < 7 ? 5 : 10) * mag, out = [];
  for (let v = Math.ceil(lo / step - 1e-9) * step; v <= hi + step * 1e-9; v += step) out.push(v);
  return { vals: out, step: step };
}
function tickText(v, step) {
  if (Math.abs(v) < step * 1e-6) return "0";
  const d = Math.max(0, -Math.floor(Math.log10(step) + 1e-9));
  return d <= 5 ? v.toFixed(d) : v.toExponential(1);
}
function esc(s) { return String(s).replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" })[c]); }
// ---- simulator: print-process noise on the factors through the model's predictive distribution ----
// Each draw perturbs the continuous factors by independent normal noise (sd per factor); at the
// perturbed design the predictive t distribution gives the chance of landing within the tolerance
// exactly, so the defect rate is 1 - the mean of those chances (Monte Carlo over the noise only),
// with the Monte Carlo standard error of that mean.
function rng(seed) {
  let a = seed >>> 0;
  const uniform = () => {
    a = (a + 0x6D2B79F5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return (((t ^ (t >>> 14)) >>> 0) + 0.5) / 4294967296;
  };
  let spare = null;
  return () => {
    if (spare !== null) { const s = spare; spare = null; return s; }
    const rad = Math.sqrt(-2 * Math.log(uniform())), th = 2 * Math.PI * uniform();
    spare = rad * Math.sin(th);
    return rad * Math.cos(th);
  };
}
const noise = Object.assign({}, D.noise);
const noiseError = {}; // factor name -> the message beside its noise box (no defect rate until fixed)
// the draws put a factor at or below 0 (a noise larger than the part): the model has no value there,
// so no rate is given; `nonphysical` is their share and `where` the factors they hit
function simulate(x) {
  const n = D.mc_draws, normal = rng(20251125), out = {};
  const rs = R.filter((r) => r.predictable && limitsOf(goals[r.name]));
  for (const r of rs) out[r.name] = { sum: 0, sum2: 0 };
  let outside = 0, nonphysical = 0;
  const where = new Set();
  for (let i = 0; i < n; i++) {
    const y = Object.assign({}, x);
    for (const f of FC) y[f.name] += (noise[f.name] || 0) * normal();
    if (FC.some((f) => y[f.name] < f.low || y[f.name] > f.high)) outside++;
    const hit = FC.filter((f) => y[f.name] <= 0);
    if (hit.length) { nonphysical++; hit.forEach((f) => where.add(f.name)); continue; }
    for (const r of rs) { const p = pGoal(r, predict(r, y), goals[r.name]); out[r.name].sum += p; out[r.name].sum2 += p * p; }
  }
  for (const r of rs) {
    const o = out[r.name], mean = o.sum / n, v = Math.max(o.sum2 / n - mean * mean, 0) * n / (n - 1);
    o.defect = 1 - mean; o.se = Math.sqrt(v / n); o.noiseless = 1 - pGoal(r, predict(r, x), goals[r.name]);
  }
  return { draws: n, outside: outside / n, responses: out, nonphysical: nonphysical / n, where: [...where] };
}
function buildNoise() {
  const box = document.getElementById("noise");
  for (const f of FC) {
    const l = document.createElement("label");
    l.innerHTML = "<span>" + esc(f.name) + " sd (" + esc(f.unit) + ")</span>";
    const inp = document.createElement("input"), err = document.createElement("div"), item = document.createElement("div");
    Object.assign(inp, { type: "text", id: "noise-" + f.name, className: "num", value: sig(noise[f.name] || 0, 6) });
    inp.setAttribute("inputmode", "decimal");
    inp.setAttribute("aria-label", "print noise, standard deviation of " + f.name + " (" + f.unit + ")");
    Object.assign(err, { className: "err", id: "noise-err-" + f.name }); err.setAttribute("role", "alert");
    inp.setAttribute("aria-describedby", err.id);
    // read strictly, as the other typed boxes ("0,5" is named, never read as 5; a negative sd refused)
    inp.oninput = () => {
      const n = parseTyped(inp.value, "0.1"), bad = n.error ? f.name + " sd: " + n.error :
        !(n.value >= 0 && isFinite(n.value)) ? f.name + " sd " + sig(n.value, 6) + " " + f.unit + " must be 0 or more" : "";
      err.textContent = bad; inp.setAttribute("aria-invalid", bad ? "true" : "false");
      if (bad) noiseError[f.name] = bad; else { delete noiseError[f.name]; noise[f.name] = n.value; }
      renderSim();
    };
    l.appendChild(inp); item.appendChild(l); item.appendChild(err); box.appendChild(item);
  }
  document.getElementById("sim-about").textContent = "Each of " + D.mc_draws + " draws adds independent normal noise (standard deviation below, rig units; defaults: " +
    FC.map((f) => sig(D.noise[f.name] || 0, 3) + " " + f.unit + " on " + f.name).join(", ") +
    ") to the continuous factors; the model's predictive distribution at each draw gives the share of joints outside the tolerance. \u00b1: 95 % Monte Carlo error.";
}
// the defect rates in % with as many decimals as the 95 % Monte Carlo error supports, and that error
function mcText(o) {
  const e = 196 * o.se, d = e > 0 ? Math.min(3, Math.max(1, 1 - Math.floor(Math.log10(e)))) : 1;
  return (100 * o.defect).toFixed(d) + " % \u00b1 " + e.toFixed(d) + " % with print noise, " + (100 * o.noiseless).toFixed(d) + " % without";
}
function renderSim() {
  const el = document.getElementById("sim"), bad = Object.values(noiseError);
  if (bad.length) { el.textContent = "no defect rate: " + bad.join("; "); return; }
  const s = simulate(asShown()), names = Object.keys(s.responses);
  if (!names.length) { el.textContent = toleranceError ? "no defect rate: " + toleranceError : "set a target on a predictable response to get a defect rate"; return; }
  if (s.nonphysical > 0) {
    el.textContent = "no defect rate: " + (100 * s.nonphysical).toFixed(1) + " % of the draws put " + s.where.join(" and ") + " at or below 0, where the model has no value (a noise larger than the part): lower its sd";
    return;
  }
  el.innerHTML = names.map((n) => {
    const o = s.responses[n];
    return '<div id="sim-' + n + '" data-defect="' + o.defect + '" data-se="' + o.se + '" data-noiseless="' + o.noiseless + '">' + esc(n) + ": defect rate (outside " + limitsText(R.find((r) => r.name === n), goals[n]) + ") " +
      mcText(o) + " (" + s.draws + " draws)</div>";
  }).join("") + (s.outside > 0 ? '<div class="sub">' + (100 * s.outside).toFixed(1) + " % of draws fall outside the tested ranges: predicted by extrapolation</div>" : "");
}
// ---- remembered settings: a table, copied as designer export command lines or as JSON for --from ----
const KEY = "flexjoint-profiler:" + D.surrogate_id + ":" + D.axis;
let memory = [];
try { memory = JSON.parse(localStorage.getItem(KEY) || "[]"); } catch (e) { memory = []; }
function asShown() { return asPrinted(Object.assign({}, state)); }
function remember() {
  const x = asShown(), s = score(x), pred = {};
  for (const r of R) pred[r.quantity] = { value: s.pred[r.name].value, low: s.pred[r.name].low, high: s.pred[r.name].high };
  memory.push({ params: x, any: solidAt(x) ? ["density"] : [], predicted: pred, p_within: s.p, desirability: s.d, probability: s.prob });
  saveMemory();
}
function saveMemory() { try { localStorage.setItem(KEY, JSON.stringify(memory)); } catch (e) { /* a private window: this page only */ } renderMemory(); }
// the page's surrogate on a command line (" --surrogate mine.json"), "" for the shipped one
function surrogateFlag() { return D.surrogate_flag ? " " + D.surrogate_flag : ""; }
function commandLine(m, i) {
  return "designer export fmu " + F.map((f) => "--" + f.name + " " + sig(m.params[f.name], 6)).join(" ") + (D.axis === "x" ? "" : " --axis " + D.axis) + surrogateFlag() + " -o joint" + (i + 1) + ".fmu";
}
function suggestionJson() {
  const goal = (q) => { const r = R.find((x) => x.quantity === q), g = r && goals[r.name]; return !g ? null : g.value !== null ? g.value : g.kind; };
  return JSON.stringify({ axis: D.axis, targets: { k: goal("k"), c: goal("c") }, tolerance: tolerance, surrogate_id: D.surrogate_id, fixed: {},
    statements: ["settings remembered on the profiler page"], candidates: memory.map((m) => ({ params: m.params, any: m.any, predicted: m.predicted,
      p_within: m.p_within, probability: m.probability, desirability: m.desirability })) }, null, 1);
}
function copyText(text) {
  const ta = document.getElementById("export-text");
  ta.value = text;
  try { navigator.clipboard.writeText(text).catch(() => { ta.select(); }); } catch (e) { ta.select(); }
}
function renderMemory() {
  const t = document.getElementById("memory");
  const head = "<tr><th scope=col>#</th>" + F.map((f) => "<th scope=col>" + esc(f.name) + " (" + esc(f.unit) + ")</th>").join("") +
    R.map((r) => "<th scope=col>" + esc(r.name) + " (" + esc(r.unit) + ")</th>").join("") + "<th scope=col>P</th><th scope=col>D</th><th scope=col>copy</th></tr>";
  t.innerHTML = head + memory.map((m, i) => "<tr><td>" + (i + 1) + "</td>" + F.map((f) => "<td>" + (m.any.includes(f.name) ? "any (solid)" : sig(m.params[f.name], 4)) + "</td>").join("") +
    R.map((r) => "<td>" + sig(m.predicted[r.quantity].value, 3) + "</td>").join("") + "<td>" + (m.p_within === null ? "" : (100 * m.p_within).toFixed(0) + " %") + "</td><td>" +
    (m.desirability === null ? "" : m.desirability.toFixed(2)) + '</td><td><button id="copy-cmd-' + (i + 1) + '" aria-label="copy the designer export command of setting ' + (i + 1) + '">command</button></td></tr>').join("");
  memory.forEach((m, i) => { document.getElementById("copy-cmd-" + (i + 1)).onclick = () => copyText(commandLine(m, i)); });
  document.getElementById("copy-json").disabled = document.getElementById("forget").disabled = !memory.length;
}
// ---- what is near the current setting ----
function near(j, skip, runs) {
  for (const f of F) {
    if (f.name === skip) continue;
    const v = (runs || D.runs)[f.name][j], s = state[f.name];
    if (f.categorical ? Math.abs(v - s) > 1e-9 : Math.abs(v - s) > NEAR * (f.high - f.low) + 1e-9) return false;
  }
  return true;
}
// ---- one panel: response r against factor f, the others at the sliders (a drawing and its text) ----
const PW = 176, PH = 160, ML = 50, MR = 10, MT = 8, MB = 36;
function xScale(f) {
  const n = f.categorical ? f.levels.length : CURVE;
  return f.categorical ? (i) => ML + (PW - ML - MR) * (i + 0.5) / n : (v) => ML + (PW - ML - MR) * (v - f.low) / (f.high - f.low);
}
function panel(r, f, first) {
  const [ylo, yhi] = r.range, ys = (v) => MT + (PH - MT - MB) * (1 - (v - ylo) / (yhi - ylo));
  const cat = f.categorical, xpos = xScale(f), g = goals[r.name];
  const x = Object.assign({}, state), pts = [];
  const lvl = (v) => f.levels.findIndex((l) => Math.abs(l - v) < 1e-9);
  if (cat) f.levels.forEach((lv) => { x[f.name] = lv; pts.push([lv, predict(r, x)]); });
  else for (let i = 0; i < CURVE; i++) { const v = f.low + (f.high - f.low) * i / (CURVE - 1); x[f.name] = v; pts.push([v, predict(r, x)]); }
  const cur = predict(r, state), vals = pts.map(([, p]) => p.value), pinned = f.name === "density" && solidAt(state);
  const label = r.name + " against " + f.name + ": " + (pinned ? "flat, the part prints solid at this width or height; " :
    "from " + sig(Math.min(...vals), 3) + " to " + sig(Math.max(...vals), 3) + " " + r.unit + " over " + (cat ? f.levels.map((v) => sig(v, 3)).join(", ") : sig(f.low, 3) + " to " + sig(f.high, 3)) + " " + f.unit + "; ") +
    "at " + sig(state[f.name], 4) + " " + f.unit + ": " + sig(cur.value, 3) + " " + r.unit + " (95 % PI " + sig(cur.low, 3) + " to " + sig(cur.high, 3) + ")";
  let s = '<svg viewBox="0 0 ' + PW + " " + PH + '" role="img" aria-label="' + esc(label) + '" data-response="' + r.name + '" data-factor="' + f.name + '">';
  s += '<clipPath id="c-' + r.name + f.name + '"><rect x="' + ML + '" y="' + MT + '" width="' + (PW - ML - MR) + '" height="' + (PH - MT - MB) + '"/></clipPath>';
  const yt = niceTicks(ylo, yhi, 4);
  for (const v of yt.vals) {
    s += '<line x1="' + ML + '" x2="' + (PW - MR) + '" y1="' + ys(v) + '" y2="' + ys(v) + '" stroke="#e6e9ee"/>';
    s += '<text x="' + (ML - 4) + '" y="' + (ys(v) + 4) + '" font-size="11" text-anchor="end">' + tickText(v, yt.step) + "</text>";
  }
  if (first) s += '<text transform="translate(11,' + ((PH - MB + MT) / 2) + ') rotate(-90)" font-size="11.5" text-anchor="middle">' + esc(r.name + " (" + r.unit + ")") + "</text>";
  s += '<g clip-path="url(#c-' + r.name + f.name + ')">';
  if (f.printable_min !== null && f.printable_min > f.low)
    s += '<rect x="' + ML + '" y="' + MT + '" width="' + (xpos(Math.min(f.printable_min, f.high)) - ML) + '" height="' + (PH - MT - MB) + '" fill="#b3261e" opacity="0.08"/>';
  if (cat) pts.forEach(([, p], i) => {
    const X = xpos(i);
    s += '<line x1="' + X + '" x2="' + X + '" y1="' + ys(p.low) + '" y2="' + ys(p.high) + '" stroke="#5b7fcf" stroke-width="6" opacity="0.45"/>';
    s += '<circle cx="' + X + '" cy="' + ys(p.value) + '" r="4" fill="#1f5fbf"/>';
  });
  else {
    const lo = [], hi = [], mid = [];
    for (const [v, p] of pts) {
      const X = xpos(v).toFixed(2);
      lo.push(X + "," + ys(p.low).toFixed(2)); hi.unshift(X + "," + ys(p.high).toFixed(2)); mid.push(X + "," + ys(p.value).toFixed(2));
    }
    s += '<polygon points="' + lo.concat(hi).join(" ") + '" fill="#5b7fcf" opacity="0.25"/>';
    s += '<polyline points="' + mid.join(" ") + '" fill="none" stroke="#1f5fbf" stroke-width="2"/>';
  }
  s += bandSvg(g, ys);
  for (let j = 0; j < D.runs[r.name].length; j++) {
    if (!near(j, f.name)) continue;
    const v = D.runs[f.name][j], X = cat ? xpos(lvl(v)) + 9 : xpos(v);
    s += '<circle class="run" cx="' + X + '" cy="' + ys(D.runs[r.name][j]) + '" r="3" fill="#222" opacity="0.75"><title>run ' + (j + 1) + ": " + sig(D.runs[r.name][j], 3) + " " + r.unit + "</title></circle>";
  }
  // the user's own prints (a calibrated surrogate): orange diamonds, near the setting as the study's runs
  const mine = D.mine, my = mine && mine[r.name];
  if (my) for (let j = 0; j < my.length; j++) {
    if (my[j] === null || !near(j, f.name, mine)) continue;
    const v = mine[f.name][j], X = cat ? xpos(lvl(v)) - 9 : xpos(v), Y = ys(my[j]);
    s += '<path class="mine" d="M' + X + " " + (Y - 5) + "l5 5l-5 5l-5 -5z" + '" fill="#e8590c" stroke="#fff"><title>your print ' + (j + 1) + ": " + sig(my[j], 3) + " " + r.unit + "</title></path>";
  }
  const cx = cat ? xpos(lvl(state[f.name])) : xpos(state[f.name]);
  s += '<line x1="' + cx + '" x2="' + cx + '" y1="' + MT + '" y2="' + (PH - MB) + '" stroke="#b3261e" stroke-width="1"/></g>';
  s += '<rect x="' + ML + '" y="' + MT + '" width="' + (PW - ML - MR) + '" height="' + (PH - MT - MB) + '" fill="none" stroke="#8a93a3"/>';
  s += '<circle class="current" cx="' + cx + '" cy="' + ys(cur.value) + '" r="4.5" fill="#fff" stroke="#b3261e" stroke-width="2"/>';
  if (pinned) s += '<text x="' + ((ML + PW - MR) / 2) + '" y="' + (MT + 14) + '" font-size="11" text-anchor="middle" fill="#8a4b00">solid: no effect</text>';
  if (cat) f.levels.forEach((lv, i) => { s += '<text x="' + xpos(i) + '" y="' + (PH - MB + 14) + '" font-size="11" text-anchor="middle">' + sig(lv, 3) + "</text>"; });
  else {
    const xt = niceTicks(f.low, f.high, 3);
    for (const v of xt.vals) s += '<text x="' + xpos(v) + '" y="' + (PH - MB + 14) + '" font-size="11" text-anchor="middle">' + tickText(v, xt.step) + "</text>";
  }
  s += '<text x="' + ((ML + PW - MR) / 2) + '" y="' + (PH - 5) + '" font-size="11.5" text-anchor="middle">' + esc(f.name + " (" + f.unit + ")") + "</text>";
  return s + "</svg>";
}
// the goal's limits (+- the tolerance, or low and high) drawn over the interval shading: an orange
// fill and solid red edges, so the band reads against the blue; the target itself dashed
function bandSvg(g, ys) {
  const l = limitsOf(g);
  if (!l) return "";
  const top = ys(l[1]), bottom = ys(l[0]), edge = (y) => '<line class="band-edge" x1="' + ML + '" x2="' + (PW - MR) + '" y1="' + y + '" y2="' + y + '" stroke="#b3261e" stroke-width="1.5"/>';
  let s = '<rect class="band" x="' + ML + '" width="' + (PW - ML - MR) + '" y="' + top + '" height="' + (bottom - top) + '" fill="#f08c00" opacity="0.35"/>' + edge(top) + edge(bottom);
  if (g.kind === "target") s += '<line x1="' + ML + '" x2="' + (PW - MR) + '" y1="' + ys(g.value) + '" y2="' + ys(g.value) + '" stroke="#7a1a14" stroke-width="1.5" stroke-dasharray="5 3"/>';
  return s;
}
// click or drag inside a panel sets its factor (a categorical one to the nearest level)
let dragging = null;
function setFromPanel(ev) {
  const svg = document.querySelector('svg[data-response="' + dragging.r + '"][data-factor="' + dragging.f + '"]');
  const f = F.find((g) => g.name === dragging.f), box = svg.getBoundingClientRect(), u = ((ev.clientX - box.left) * PW / box.width - ML) / (PW - ML - MR);
  if (f.categorical) state[f.name] = f.levels[Math.min(f.levels.length - 1, Math.max(0, Math.floor(u * f.levels.length)))];
  else state[f.name] = Number((Math.round(Math.min(f.high, Math.max(f.low, f.low + u * (f.high - f.low))) / f.step) * f.step).toFixed(6));
  syncSliders(); render();
}
function panelEvents() {
  const rows = document.getElementById("rows");
  rows.addEventListener("pointerdown", (ev) => {
    const svg = ev.target.closest("svg[data-factor]");
    if (!svg || locked[svg.dataset.factor] || ev.button !== 0) return;
    dragging = { r: svg.dataset.response, f: svg.dataset.factor };
    ev.preventDefault(); setFromPanel(ev);
  });
  window.addEventListener("pointermove", (ev) => { if (dragging) setFromPanel(ev); });
  window.addEventListener("pointerup", () => { dragging = null; });
  window.addEventListener("pointercancel", () => { dragging = null; });
}
