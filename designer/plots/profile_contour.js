// ---- contour view: two continuous factors, the others at the sliders (JMP's Contour Profiler) ----
// Each cell is shaded where the prediction at its centre meets every stated goal on a predictable
// response (within its limits), and coloured by the joint P there; the current design is the ring.
// Hovering reads the exact P at the pointer; a click sets both factors (unless locked).
const CN = 30, CW = 330, CH = 300, CL = 52, CR = 12, CT = 10, CB = 40;
const contourAxes = { x: "width", y: "height" };
function contourFactor(axis) { return FC.find((f) => f.name === contourAxes[axis]); }
function buildContour() {
  const opts = (axis) => FC.map((f) => "<option" + (f.name === contourAxes[axis] ? " selected" : "") + ">" + f.name + "</option>").join("");
  document.getElementById("contour-pick").innerHTML =
    '<label for="contour-x">across</label><select id="contour-x">' + opts("x") + '</select><label for="contour-y">up</label><select id="contour-y">' + opts("y") + "</select>";
  for (const axis of ["x", "y"]) {
    const el = document.getElementById("contour-" + axis);
    el.onchange = () => {
      const other = axis === "x" ? "y" : "x";
      if (el.value === contourAxes[other]) { contourAxes[other] = contourAxes[axis]; document.getElementById("contour-" + other).value = contourAxes[other]; }
      contourAxes[axis] = el.value; render();
    };
  }
  const box = document.getElementById("contour");
  box.addEventListener("pointermove", (ev) => { const at = contourAt(ev); if (at) showContourPoint(at); });
  box.addEventListener("click", (ev) => {
    const at = contourAt(ev);
    if (!at) return;
    const fx = contourFactor("x"), fy = contourFactor("y");
    for (const [f, v] of [[fx, at.x], [fy, at.y]]) if (!locked[f.name]) state[f.name] = Number((Math.round(v / f.step) * f.step).toFixed(6));
    syncSliders(); render();
  });
}
// the factor values under a pointer event, or null outside the plot
function contourAt(ev) {
  const svg = document.querySelector("#contour svg");
  if (!svg) return null;
  const b = svg.getBoundingClientRect(), px = (ev.clientX - b.left) * CW / b.width, py = (ev.clientY - b.top) * CH / b.height;
  const u = (px - CL) / (CW - CL - CR), v = 1 - (py - CT) / (CH - CT - CB);
  if (u < 0 || u > 1 || v < 0 || v > 1) return null;
  const fx = contourFactor("x"), fy = contourFactor("y");
  return { x: fx.low + u * (fx.high - fx.low), y: fy.low + v * (fy.high - fy.low) };
}
// what the design with the two factors at (x, y) and the rest at the sliders predicts and meets
function contourScore(x, y) {
  const d = Object.assign({}, state);
  d[contourAxes.x] = x; d[contourAxes.y] = y;
  const sc = score(d);
  let met = null;
  for (const r of R) {
    const l = limitsOf(goals[r.name]);
    if (!l || !r.predictable) continue;
    const v = sc.pred[r.name].value;
    met = (met === null ? true : met) && v >= l[0] && v <= l[1];
  }
  return { sc: sc, met: met };
}
function showContourPoint(at) {
  const c = contourScore(at.x, at.y), el = document.getElementById("contour-read"), fx = contourFactor("x"), fy = contourFactor("y");
  Object.assign(el.dataset, { x: at.x, y: at.y, p: c.sc.joint === null ? "" : c.sc.joint, met: String(c.met) });
  el.textContent = "at " + fx.name + " " + sig(at.x, 4) + " " + fx.unit + ", " + fy.name + " " + sig(at.y, 4) + " " + fy.unit + ": " +
    R.map((r) => r.name + " " + sig(c.sc.pred[r.name].value, 3) + " " + r.unit).join(", ") + (c.sc.joint === null ? "" : "; P(every stated goal) " + pct(c.sc.joint)) +
    (c.met === null ? "" : c.met ? "; predicted within every goal" : "; predicted outside a goal");
}
// a light-to-dark green for P in [0, 1] (the shaded region), pale grey outside it
function contourFill(met, p) {
  if (!met) return "#eef0f3";
  const t = p === null ? 0.5 : Math.min(1, Math.max(0, p));
  return "rgb(" + Math.round(196 - 150 * t) + "," + Math.round(232 - 90 * t) + "," + Math.round(196 - 130 * t) + ")";
}
function renderContour() {
  const fx = contourFactor("x"), fy = contourFactor("y"), box = document.getElementById("contour");
  const w = (CW - CL - CR) / CN, h = (CH - CT - CB) / CN, anyGoal = R.some((r) => r.predictable && limitsOf(goals[r.name]));
  const X = (v) => CL + (CW - CL - CR) * (v - fx.low) / (fx.high - fx.low), Y = (v) => CT + (CH - CT - CB) * (1 - (v - fy.low) / (fy.high - fy.low));
  let s = '<svg viewBox="0 0 ' + CW + " " + CH + '" role="img" aria-labelledby="contour-about">', inside = 0;
  for (let i = 0; i < CN; i++) for (let j = 0; j < CN; j++) {
    const cx = fx.low + (i + 0.5) / CN * (fx.high - fx.low), cy = fy.low + (j + 0.5) / CN * (fy.high - fy.low), c = contourScore(cx, cy);
    if (c.met) inside++;
    s += '<rect class="cell" x="' + (CL + i * w).toFixed(2) + '" y="' + (CT + (CN - 1 - j) * h).toFixed(2) + '" width="' + (w + 0.3).toFixed(2) + '" height="' + (h + 0.3).toFixed(2) +
      '" fill="' + contourFill(c.met, c.sc.joint) + '" data-cx="' + cx + '" data-cy="' + cy + '" data-met="' + c.met + '"/>';
  }
  s += '<rect x="' + CL + '" y="' + CT + '" width="' + (CW - CL - CR) + '" height="' + (CH - CT - CB) + '" fill="none" stroke="#8a93a3"/>';
  for (const [f, axis] of [[fx, "x"], [fy, "y"]]) {
    const t = niceTicks(f.low, f.high, 4);
    for (const v of t.vals) s += axis === "x" ? '<text x="' + X(v) + '" y="' + (CH - CB + 14) + '" font-size="11" text-anchor="middle">' + tickText(v, t.step) + "</text>"
      : '<text x="' + (CL - 4) + '" y="' + (Y(v) + 4) + '" font-size="11" text-anchor="end">' + tickText(v, t.step) + "</text>";
  }
  s += '<text x="' + ((CL + CW - CR) / 2) + '" y="' + (CH - 6) + '" font-size="11.5" text-anchor="middle">' + esc(fx.name + " (" + fx.unit + ")") + "</text>";
  s += '<text transform="translate(12,' + ((CT + CH - CB) / 2) + ') rotate(-90)" font-size="11.5" text-anchor="middle">' + esc(fy.name + " (" + fy.unit + ")") + "</text>";
  s += '<circle class="current" cx="' + X(state[fx.name]) + '" cy="' + Y(state[fy.name]) + '" r="6" fill="none" stroke="#b3261e" stroke-width="2.5"/></svg>';
  box.innerHTML = s;
  const share = inside / (CN * CN);
  document.getElementById("contour-about").textContent = !anyGoal ? fx.name + " against " + fy.name + ": set a target or limits on a predictable response to shade where it is met" :
    fx.name + " against " + fy.name + ", the other factors at the sliders: shaded (darker: higher P of every stated goal) where the prediction meets every goal, " +
    (100 * share).toFixed(0) + " % of the plane; ring: the current design. Hover for P, click to set both.";
  box.dataset.share = share;
}
