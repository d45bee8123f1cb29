// ---- the page ----
function accuracyText(r) {
  const a = r.accuracy, c = r.calibrated;
  if (c && c.loo_user) return "your " + c.loo_user.n + " prints, each predicted from the others: median error " + c.loo_user.mape.toFixed(0) + " %, " +
    (100 * c.loo_user.coverage95).toFixed(0) + " % inside the 95 % PI; printer factor " + sig(c.printer_factor.value, 3) + " [" + sig(c.printer_factor.low, 3) + ", " + sig(c.printer_factor.high, 3) + "]";
  return a.kind + ": Q2 " + a.q2.toFixed(2) + ", RMSE " + sig(a.rmse, 3) + " " + r.unit + ", MAPE " + a.mape.toFixed(0) + " %, 95 % PI coverage " + (100 * a.coverage95).toFixed(0) + " %";
}
function valueText(f) {
  if (f.name === "density" && solidAt(state)) return "100 % (solid)";
  return sig(state[f.name], 4) + " " + f.unit;
}
function buildControls() {
  const box = document.getElementById("controls");
  for (const f of F) {
    const d = document.createElement("div"); d.className = "ctl";
    const out = document.createElement("output"); out.id = "v-" + f.name;
    if (f.categorical) {
      d.innerHTML = '<span class="name" id="n-' + f.name + '" title="' + esc(f.label) + '">' + esc(f.name) + " (" + esc(f.unit) + ")</span>";
      const lv = document.createElement("div"); lv.className = "levels"; lv.setAttribute("role", "group"); lv.setAttribute("aria-labelledby", "n-" + f.name);
      for (const v of f.levels) {
        const b = document.createElement("button"); b.textContent = sig(v, 3); b.dataset.factor = f.name; b.dataset.level = v;
        b.id = "b-" + f.name + "-" + v; b.setAttribute("aria-label", f.name + " " + sig(v, 3) + " " + f.unit);
        b.onclick = () => { state[f.name] = v; render(); };
        lv.appendChild(b);
      }
      d.appendChild(lv);
    } else {
      d.innerHTML = '<label class="name" for="s-' + f.name + '" title="' + esc(f.label) + '">' + esc(f.name) + " (" + esc(f.unit) + ")</label>";
      const tr = document.createElement("div"); tr.className = "track";
      const inp = document.createElement("input");
      Object.assign(inp, { type: "range", id: "s-" + f.name, min: f.low, max: f.high, step: f.step, value: state[f.name] });
      inp.setAttribute("aria-describedby", "v-" + f.name); // Chromium reads a native slider's value without aria-valuetext
      inp.oninput = () => { state[f.name] = parseFloat(inp.value); document.getElementById("e-" + f.name).textContent = ""; render(); };
      const sc = document.createElement("div"); sc.className = "scale"; sc.setAttribute("aria-hidden", "true");
      const u = f.printable_min === null ? -1 : (f.printable_min - f.low) / (f.high - f.low);
      let h = u >= 0 && u <= 1 ? "" : '<span style="left:0">' + sig(f.low, 4) + "</span>";
      h += '<span style="right:0">' + sig(f.high, 4) + "</span>";
      if (u >= 0 && u <= 1) h += '<span class="pm" style="left:' + (100 * u).toFixed(1) + '%" title="narrowest printable: two ' + D.wall_mm + " mm walls and one " + D.nozzle_mm + ' mm line">' + sig(f.printable_min, 3) + " printable min</span>";
      sc.innerHTML = h; tr.appendChild(inp); tr.appendChild(sc); d.appendChild(tr);
    }
    out.setAttribute("aria-hidden", "true");
    d.appendChild(out);
    if (!f.categorical) { // the value typed: kept in step with the slider, clamped to the range with a message
      out.className = "sr";
      const t = document.createElement("input");
      Object.assign(t, { type: "text", id: "t-" + f.name, value: sig(state[f.name], 6), className: "num value" });
      t.setAttribute("inputmode", "decimal");
      t.setAttribute("aria-label", f.name + " value (" + f.unit + ")");
      t.setAttribute("aria-describedby", "e-" + f.name);
      t.onchange = () => typeValue(f, t); // on Enter and on leaving the box
      d.appendChild(t);
      const e = document.createElement("div"); e.className = "err"; e.id = "e-" + f.name; e.setAttribute("role", "alert");
      d.appendChild(e);
    }
    const lk = document.createElement("label"); lk.className = "lock"; lk.title = "hold " + f.name + " when maximizing";
    lk.innerHTML = '<input type="checkbox" id="lock-' + f.name + '" aria-label="lock ' + esc(f.name) + ' (hold it when maximizing)"><span>lock</span>';
    lk.firstChild.onchange = (ev) => { locked[f.name] = ev.target.checked; render(); };
    d.appendChild(lk); box.appendChild(d);
  }
}
// a factor value typed into its box: read strictly, rounded to the printable step and clamped to the
// tested range; what was changed is said beside the box
function typeValue(f, box) {
  const msg = document.getElementById("e-" + f.name), n = parseTyped(box.value, sig(f.low + 0.5 * (f.high - f.low), 3));
  if (n.error) { msg.textContent = f.name + ": " + n.error; box.setAttribute("aria-invalid", "true"); return; }
  const v = Number((Math.round(n.value / f.step) * f.step).toFixed(6)), clamped = Math.min(f.high, Math.max(f.low, v));
  msg.textContent = clamped !== v ? f.name + " " + sig(n.value, 6) + " " + f.unit + " is outside the tested range " + sig(f.low, 4) + " to " + sig(f.high, 4) + " " + f.unit + ": set to " + sig(clamped, 6) + " " + f.unit :
    v !== n.value ? f.name + " " + sig(n.value, 8) + " " + f.unit + " rounded to the printable step: " + sig(v, 6) + " " + f.unit : "";
  box.setAttribute("aria-invalid", "false");
  state[f.name] = clamped; syncSliders(); render();
}
function designText(p, any) {
  return F.map((f) => f.name + " " + (any.includes(f.name) ? "any (solid)" : sig(p[f.name], 4) + " " + f.unit)).join(", ");
}
function applyDesign(p) { for (const f of F) state[f.name] = p[f.name]; syncSliders(); render(); }
function buildSuggestions() {
  const box = document.getElementById("suggestions");
  if (!D.suggestions.length) { document.getElementById("sugbox").style.display = "none"; return; }
  for (const c of D.suggestions) {
    const b = document.createElement("button"); b.id = "sug-" + c.rank;
    b.innerHTML = "<b>#" + c.rank + (c.p_within === null ? "" : ", P " + (100 * c.p_within).toFixed(0) + " %") + ":</b> " + esc(designText(c.params, c.any)) +
      (c.inside ? "" : '<span class="why">not shown: ' + esc(c.outside.join("; ")) + " (an extrapolation the sliders cannot reach)</span>") +
      '<span class="why stale-why"></span>';
    if (!c.inside) b.disabled = true;
    b.onclick = () => applyDesign(c.params);
    box.appendChild(b);
  }
}
function syncSliders() {
  for (const f of FC) { document.getElementById("s-" + f.name).value = state[f.name]; document.getElementById("t-" + f.name).value = sig(state[f.name], 6); }
}
function buildRows() {
  const rows = document.getElementById("rows");
  for (const r of R) {
    const d = document.createElement("div"); d.className = "row";
    let panels = '<div class="panels" id="panels-' + r.name + '"></div>';
    if (!r.predictable && !r.calibrated) panels = '<details class="flat" aria-label="' + esc(r.name) + ' panels"><summary>' + esc(r.name) + " against the factors: flat, the same prediction for every design</summary>" + panels + "</details>";
    d.innerHTML = '<div class="summary"><h3>' + esc(r.name) + " (" + esc(r.unit) + ')</h3><div class="pred" id="pred-' + r.name + '"></div>' +
      '<div class="pi" id="pi-' + r.name + '"></div>' + (r.predictable ? "" : '<div class="warn">' + esc(r.calibrated ? r.calibrated.statement : r.statement) + "</div>") +
      '<div class="tgt" id="tgt-' + r.name + '"></div><div class="acc">' + esc(accuracyText(r)) + "</div></div>" + panels;
    rows.appendChild(d);
  }
}
// the sticky readout: each prediction and the joint P, in view while the sliders move (a phone's first screen)
function renderReadout(sc) {
  const parts = R.map((r) => {
    const p = sc.pred[r.name];
    return '<span id="ro-' + r.name + '">' + esc(r.name) + " <b>" + sig(p.value, 3) + "</b> [" + sig(p.low, 2) + ", " + sig(p.high, 2) + "] " + esc(r.unit) + (r.predictable ? "" : " (not predictable)") + "</span>";
  });
  const named = R.filter((r) => r.name in sc.prob).map((r) => r.name);
  if (sc.joint !== null) parts.push('<span id="ro-p">P(' + named.join(" and ") + " met) <b>" + pct(sc.joint) + "</b></span>");
  const out = R.map((r) => goals[r.name] && outOfReach(r, goals[r.name])).filter((t) => t);
  if (out.length) parts.push('<span class="out">' + esc(out.map((t) => t.split(":")[0]).join("; ")) + "</span>");
  const bad = Object.keys(goalError);
  if (bad.length) parts.push('<span class="out">goal error: ' + esc(bad.join(", ")) + "</span>");
  if (toleranceError) parts.push('<span class="out">tolerance error</span>');
  document.getElementById("readout").innerHTML = parts.join(" ");
}
// why maximize cannot run now, or "" when it can
function maximizeBlocked() {
  const bad = Object.keys(goalError);
  if (bad.length) return "fix the goal of " + bad.join(" and ") + " first";
  if (toleranceError) return "fix the tolerance first";
  if (!Object.keys(weights()).length) return "set a goal (target, limits, min or max) on a predictable response first";
  return "";
}
function render() {
  const typing = document.activeElement;
  for (const f of F) {
    const o = document.getElementById("v-" + f.name), txt = valueText(f);
    o.textContent = txt;
    if (f.categorical) for (const b of document.querySelectorAll('button[data-factor="' + f.name + '"]')) {
      b.setAttribute("aria-pressed", Math.abs(+b.dataset.level - state[f.name]) < 1e-9 ? "true" : "false"); b.disabled = !!locked[f.name];
    }
    else {
      const s = document.getElementById("s-" + f.name), t = document.getElementById("t-" + f.name), pinned = f.name === "density" && solidAt(state);
      s.setAttribute("aria-valuetext", txt); s.disabled = t.disabled = !!locked[f.name] || pinned;
      if (t !== typing) t.value = pinned ? "100" : sig(state[f.name], 6);
    }
  }
  const sc = score(state);
  for (const r of R) {
    const p = sc.pred[r.name], el = document.getElementById("pred-" + r.name), g = goals[r.name];
    el.textContent = r.name + " = " + sig(p.value, 4) + " " + r.unit;
    el.dataset.value = p.value; el.dataset.low = p.low; el.dataset.high = p.high;
    document.getElementById("pi-" + r.name).textContent = "95 % PI " + sig(p.low, 3) + " to " + sig(p.high, 3) + " " + r.unit;
    const tg = document.getElementById("tgt-" + r.name);
    tg.textContent = goalText(r, p, sc.prob[r.name]);
    if (r.name in sc.prob) tg.dataset.probability = sc.prob[r.name]; else delete tg.dataset.probability;
    if (g && r.predictable) tg.dataset.desirability = desirability(g, p.value); else delete tg.dataset.desirability;
    const out = g && outOfReach(r, g);
    if (out) tg.dataset.reach = "out"; else delete tg.dataset.reach;
    tg.classList.toggle("outreach", !!out);
    document.getElementById("panels-" + r.name).innerHTML = F.map((f, i) => panel(r, f, i === 0)).join("");
  }
  const ov = document.getElementById("overall"), texts = [];
  for (const [key, v] of [["probability", sc.p], ["joint", sc.joint], ["desirability", sc.d]]) if (v !== null) ov.dataset[key] = v; else delete ov.dataset[key];
  const named = R.filter((r) => r.name in sc.prob);
  if (sc.joint !== null) texts.push("P(every stated goal met: " + named.map((r) => r.name + " " + limitsText(r, goals[r.name])).join(" and ") + ") = " + pct(sc.joint) +
    (named.length > 1 ? " (" + named.map((r) => r.name + " " + pct(sc.prob[r.name])).join(" \u00d7 ") + ": given the model the responses scatter independently)" : ""));
  const blind = named.filter((r) => !r.predictable);
  // a calibrated page: the user's prints pin an unpredictable response down near them, so its chance
  // does change with the setting (though maximize does not act on it)
  const their = (rs) => (rs.length > 1 ? "their" : "its");
  const flat = blind.filter((r) => !r.calibrated), pinned = blind.filter((r) => r.calibrated);
  const because = [];
  if (flat.length) because.push(flat.map((r) => r.name).join(", ") + " not predictable: no setting changes " + their(flat) + " chance");
  if (pinned.length) because.push(pinned.map((r) => r.name).join(", ") + " not predictable from the six factors: " + their(pinned) + " chance varies with the setting only through your prints (designer calibrate)");
  if (blind.length) texts.push(because.join("; ") + "; maximize ranks by P of the predictable goals" + (sc.p === null ? "" : ", " + pct(sc.p)));
  if (sc.d !== null) texts.push("composite desirability (predictable responses) " + sc.d.toFixed(2));
  ov.textContent = texts.join("; ");
  const side = state.width <= state.height ? "width" : "height", core = state[side] - 2 * D.wall_mm;
  document.getElementById("notes").textContent = solidAt(state) ?
    "at " + sig(state[side], 3) + " mm " + side + " the two " + D.wall_mm + " mm walls leave " + Math.max(core, 0).toFixed(1) + " mm inside, at most one nozzle line: the infill density has no effect, the part prints solid and is predicted at 100 % (the density control is pinned)" : "";
  const why = maximizeBlocked();
  document.getElementById("maximize").disabled = !!why;
  document.getElementById("max-why").textContent = why;
  const stale = suggestionStale();
  for (const b of document.querySelectorAll("#suggestions button")) {
    b.classList.toggle("stale", !!stale); b.dataset.stale = stale ? "true" : "false";
    b.querySelector(".stale-why").textContent = stale || "";
  }
  renderReadout(sc);
  renderContour();
  renderTrace(sc);
  renderSim();
  document.body.dataset.renders = (+(document.body.dataset.renders || 0) + 1).toString();
}
// suggest's command line for the page's goals, or why there is none (suggest takes symmetric tolerances)
function suggestCommand() {
  const set = R.filter((r) => goals[r.name]);
  if (set.some((r) => goals[r.name].kind === "limits")) return "no designer suggest command: it takes a target \u00b1 --tolerance, not low and high limits (the search aimed at the limits' midpoint)";
  return "the same search as: designer suggest " + set.map((r) => "--" + r.quantity + " " + (goals[r.name].kind === "target" ? sig(goals[r.name].value, 6) : goals[r.name].kind)).join(" ") +
    (D.axis === "x" ? "" : " --axis " + D.axis) + surrogateFlag() + F.filter((f) => locked[f.name]).map((f) => " --fix " + f.name + "=" + sig(state[f.name], 6)).join("") +
    (Math.abs(tolerance - 0.1) > 1e-12 ? " --tolerance " + sig(100 * tolerance, 4) : "");
}
function runMaximize() {
  const st = document.getElementById("max-status"), t0 = performance.now(), blocked = maximizeBlocked();
  if (blocked) { st.textContent = blocked; return; }
  const m = maximize();
  applyDesign(m.best.x);
  const lockedNames = Object.keys(m.fixed), s = m.best.s;
  st.dataset.p = s.p === null ? "" : s.p; st.dataset.d = s.d === null ? "" : s.d; st.dataset.design = JSON.stringify(m.best.x); st.dataset.ms = (performance.now() - t0).toFixed(0);
  st.dataset.joint = s.joint === null ? "" : s.joint;
  st.textContent = "best of " + m.searched + " level combination(s) \u00d7 " + m.starts + " starts" + (lockedNames.length ? ", holding " + lockedNames.join(", ") : "") + ": " +
    (s.p === null ? "" : "P " + (100 * s.p).toFixed(1) + " %, ") + "D " + s.d.toFixed(3) + " at " + designText(m.best.x, solidAt(m.best.x) ? ["density"] : []) + "; " + suggestCommand();
}
document.getElementById("source").textContent = (D.opened_from ? "opened at " + D.opened_from + " and its goals; " : "") + "surrogate " + D.surrogate_id + "; " + (D.mine ? D.mine.density.length + " of your prints (orange diamonds, calibrated with designer calibrate) on top of the study's " : "") + D.runs.density.length +
  " measured runs (points: runs whose other factors lie within " + (100 * NEAR) + " % of their range of the sliders, same layer and raster); blue: 95 % prediction interval; orange with red edges: the goal's limits (\u00b1 the tolerance around a target, dashed). Click or drag inside a panel to set its factor.";
const tolEl = document.getElementById("tolerance");
tolEl.value = sig(100 * tolerance, 4);
tolEl.setAttribute("aria-label", "tolerance around a target, \u00b1 %");
tolEl.oninput = () => {
  const n = parseTyped(tolEl.value, "10"), err = document.getElementById("tol-err");
  const bad = n.error ? "tolerance: " + n.error : !(n.value > 0 && n.value < 100) ? "tolerance " + sig(n.value, 6) + " % must lie between 0 and 100 %" : "";
  err.textContent = bad; tolEl.setAttribute("aria-invalid", bad ? "true" : "false");
  toleranceError = bad || null;
  if (!bad) tolerance = n.value / 100;
  render();
};
document.getElementById("maximize").onclick = runMaximize;
document.getElementById("remember").onclick = remember;
document.getElementById("copy-json").onclick = () => copyText(suggestionJson());
document.getElementById("forget").onclick = () => { memory = []; saveMemory(); };
buildControls(); buildGoals(); buildSuggestions(); buildRows(); buildContour(); buildNoise(); panelEvents(); renderMemory(); render();
document.body.dataset.ready = performance.now().toFixed(1);
