// ---- P trace (JMP's desirability trace): P(every stated goal met) against each factor, the others at
// the sliders; where P peaks along each factor and how flat it is there ----
function traceCurve(f) {
  const x = Object.assign({}, state), pts = [];
  const at = (v) => { x[f.name] = v; return [v, score(x).joint]; };
  if (f.categorical) for (const lv of f.levels) pts.push(at(lv));
  else for (let i = 0; i < CURVE; i++) pts.push(at(f.low + (f.high - f.low) * i / (CURVE - 1)));
  return pts;
}
function tracePanel(f, first) {
  const ys = (p) => MT + (PH - MT - MB) * (1 - p), cat = f.categorical, xpos = xScale(f), pts = traceCurve(f);
  const lvl = (v) => f.levels.findIndex((l) => Math.abs(l - v) < 1e-9), X = (v) => (cat ? xpos(lvl(v)) : xpos(v));
  const best = pts.reduce((a, b) => (b[1] > a[1] ? b : a)), now = score(state).joint;
  const label = "P(every stated goal met) against " + f.name + ": highest " + pct(best[1]) + " at " + sig(best[0], 4) + " " + f.unit + "; at " + sig(state[f.name], 4) + " " + f.unit + ": " + pct(now);
  let s = '<svg viewBox="0 0 ' + PW + " " + PH + '" role="img" aria-label="' + esc(label) + '" data-trace="' + f.name + '" data-best="' + best[0] + '" data-pbest="' + best[1] + '">';
  for (const p of [0, 0.25, 0.5, 0.75, 1]) {
    s += '<line x1="' + ML + '" x2="' + (PW - MR) + '" y1="' + ys(p) + '" y2="' + ys(p) + '" stroke="#e6e9ee"/>';
    s += '<text x="' + (ML - 4) + '" y="' + (ys(p) + 4) + '" font-size="11" text-anchor="end">' + 100 * p + "</text>";
  }
  if (first) s += '<text transform="translate(11,' + ((PH - MB + MT) / 2) + ') rotate(-90)" font-size="11.5" text-anchor="middle">P (%)</text>';
  if (cat) pts.forEach(([v, p]) => { s += '<circle cx="' + X(v) + '" cy="' + ys(p) + '" r="4" fill="#2b8a3e"/>'; });
  else s += '<polyline points="' + pts.map(([v, p]) => X(v).toFixed(2) + "," + ys(p).toFixed(2)).join(" ") + '" fill="none" stroke="#2b8a3e" stroke-width="2"/>';
  s += '<rect x="' + ML + '" y="' + MT + '" width="' + (PW - ML - MR) + '" height="' + (PH - MT - MB) + '" fill="none" stroke="#8a93a3"/>';
  s += '<line x1="' + X(state[f.name]) + '" x2="' + X(state[f.name]) + '" y1="' + MT + '" y2="' + (PH - MB) + '" stroke="#b3261e"/>';
  s += '<circle class="current" cx="' + X(state[f.name]) + '" cy="' + ys(now) + '" r="4.5" fill="#fff" stroke="#b3261e" stroke-width="2"/>';
  if (cat) f.levels.forEach((lv, i) => { s += '<text x="' + xpos(i) + '" y="' + (PH - MB + 14) + '" font-size="11" text-anchor="middle">' + sig(lv, 3) + "</text>"; });
  else { const xt = niceTicks(f.low, f.high, 3); for (const v of xt.vals) s += '<text x="' + xpos(v) + '" y="' + (PH - MB + 14) + '" font-size="11" text-anchor="middle">' + tickText(v, xt.step) + "</text>"; }
  s += '<text x="' + ((ML + PW - MR) / 2) + '" y="' + (PH - 5) + '" font-size="11.5" text-anchor="middle">' + esc(f.name + " (" + f.unit + ")") + "</text>";
  return s + "</svg>";
}
function renderTrace(sc) {
  const row = document.getElementById("trace-row");
  row.hidden = sc.joint === null;
  if (sc.joint === null) return;
  document.getElementById("trace-now").textContent = "P(every stated goal met) = " + pct(sc.joint) + " at the sliders";
  document.getElementById("trace").innerHTML = F.map((f, i) => tracePanel(f, i === 0)).join("");
}
