// ---- the page ----
function accuracyText(r) {
  const a = r.accuracy;
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
      inp.oninput = () => { state[f.name] = parseFloat(inp.value); render(); };
      const sc = document.createElement("div"); sc.className = "scale"; sc.setAttribute("aria-hidden", "true");
      const u = f.printable_min === null ? -1 : (f.printable_min - f.low) / (f.high - f.low);
      let h = u >= 0 && u <= 1 ? "" : '<span style="left:0">' + sig(f.low, 4) + "</span>";
      h += '<span style="right:0">' + sig(f.high, 4) + "</span>";
      if (u >= 0 && u <= 1) h += '<span class="pm" style="left:' + (100 * u).toFixed(1) + '%" title="narrowest printable: two ' + D.wall_mm + " mm walls and one " + D.nozzle_mm + ' mm line">' + sig(f.printable_min, 3) + " printable min</span>";
      sc.innerHTML = h; tr.appendChild(inp); tr.appendChild(sc); d.appendChild(tr);
    }
    out.setAttribute("aria-hidden", "true");
    d.appendChild(out);
    const lk = document.createElement("label"); lk.className = "lock"; lk.title = "hold " + f.name + " when maximizing";
    lk.innerHTML = '<input type="checkbox" id="lock-' + f.name + '" aria-label="lock ' + esc(f.name) + ' (hold it when maximizing)"><span>lock</span>';
    lk.firstChild.onchange = (ev) => { locked[f.name] = ev.target.checked; render(); };
    d.appendChild(lk); box.appendChild(d);
  }
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
      (c.inside ? "" : '<span class="why">not shown: ' + esc(c.outside.join("; ")) + " (an extrapolation the sliders cannot reach)</span>");
    if (!c.inside) b.disabled = true;
    b.onclick = () => applyDesign(c.params);
    box.appendChild(b);
  }
}
function syncSliders() { for (const f of FC) document.getElementById("s-" + f.name).value = state[f.name]; }
function goalControl(r) {
  const g = r.target, kind = g ? g.kind : "none";
  return '<div class="goal"><label for="goal-kind-' + r.name + '">goal</label><select id="goal-kind-' + r.name + '" aria-label="goal for ' + r.name + '">' +
    ["none", "target", "min", "max"].map((k) => "<option" + (k === kind ? " selected" : "") + ">" + k + "</option>").join("") + "</select>" +
    '<input type="number" id="goal-value-' + r.name + '" step="any" min="0" aria-label="target ' + r.name + " (" + esc(r.unit) + ')" value="' + (g && g.value !== null ? g.value : "") + '">' +
    "<span>" + esc(r.unit) + "</span></div>";
}
function buildRows() {
  const rows = document.getElementById("rows");
  for (const r of R) {
    const d = document.createElement("div"); d.className = "row";
    let panels = '<div class="panels" id="panels-' + r.name + '"></div>';
    if (!r.predictable) panels = '<details class="flat" aria-label="' + esc(r.name) + ' panels"><summary>' + esc(r.name) + " against the factors: flat, the same prediction for every design</summary>" + panels + "</details>";
    d.innerHTML = '<div class="summary"><h3>' + esc(r.name) + " (" + esc(r.unit) + ')</h3><div class="pred" id="pred-' + r.name + '"></div>' +
      '<div class="pi" id="pi-' + r.name + '"></div>' + (r.predictable ? goalControl(r) : '<div class="warn">' + esc(r.statement) + "</div>") +
      '<div class="tgt" id="tgt-' + r.name + '"></div><div class="acc">' + esc(accuracyText(r)) + "</div></div>" + panels;
    rows.appendChild(d);
    if (!r.predictable) continue;
    const kindEl = document.getElementById("goal-kind-" + r.name), valEl = document.getElementById("goal-value-" + r.name);
    const update = () => {
      const g = makeGoal(r, kindEl.value, parseFloat(valEl.value));
      valEl.disabled = kindEl.value !== "target";
      valEl.setAttribute("aria-invalid", g === undefined ? "true" : "false");
      if (g !== undefined) { goals[r.name] = g; render(); }
    };
    kindEl.onchange = update; valEl.oninput = update; valEl.disabled = kindEl.value !== "target";
  }
}
function goalText(r, p) {
  const g = goals[r.name];
  if (!g) return "";
  if (!r.predictable) {
    if (g.kind !== "target") return "goal " + g.kind + ": cannot be acted on, no setting changes it";
    return "target " + sig(g.value, 4) + " " + r.unit + ": any design lands within \u00b1" + sig(100 * tolerance, 3) + " % with probability " + pWithin(r, p, g.value).toFixed(2) + "; no setting can be chosen for it from this data";
  }
  const d = desirability(g, p.value);
  if (g.kind !== "target") return g.kind + " (desirability bounds " + sig(g.low, 3) + " to " + sig(g.high, 3) + " " + r.unit + "): desirability " + d.toFixed(2);
  return "target " + sig(g.value, 4) + " " + r.unit + ": P(within \u00b1" + sig(100 * tolerance, 3) + " %) = " + (100 * pWithin(r, p, g.value)).toFixed(0) + " %, desirability " + d.toFixed(2);
}
function render() {
  for (const f of F) {
    const o = document.getElementById("v-" + f.name), txt = valueText(f);
    o.textContent = txt;
    if (f.categorical) for (const b of document.querySelectorAll('button[data-factor="' + f.name + '"]')) {
      b.setAttribute("aria-pressed", Math.abs(+b.dataset.level - state[f.name]) < 1e-9 ? "true" : "false"); b.disabled = !!locked[f.name];
    }
    else {
      const s = document.getElementById("s-" + f.name);
      s.setAttribute("aria-valuetext", txt); s.disabled = !!locked[f.name] || (f.name === "density" && solidAt(state));
    }
  }
  const sc = score(state);
  for (const r of R) {
    const p = sc.pred[r.name], el = document.getElementById("pred-" + r.name), g = goals[r.name];
    el.textContent = r.name + " = " + sig(p.value, 4) + " " + r.unit;
    el.dataset.value = p.value; el.dataset.low = p.low; el.dataset.high = p.high;
    document.getElementById("pi-" + r.name).textContent = "95 % PI " + sig(p.low, 3) + " to " + sig(p.high, 3) + " " + r.unit;
    const tg = document.getElementById("tgt-" + r.name);
    tg.textContent = goalText(r, p);
    if (g && g.kind === "target") tg.dataset.probability = sc.prob[r.name]; else delete tg.dataset.probability;
    if (g && r.predictable) tg.dataset.desirability = desirability(g, p.value); else delete tg.dataset.desirability;
    document.getElementById("panels-" + r.name).innerHTML = F.map((f, i) => panel(r, f, i === 0)).join("");
  }
  const ov = document.getElementById("overall");
  if (sc.d !== null) {
    ov.dataset.desirability = sc.d; if (sc.p !== null) ov.dataset.probability = sc.p; else delete ov.dataset.probability;
    ov.textContent = (sc.p === null ? "" : "P(every predictable target met) " + (100 * sc.p).toFixed(0) + " %; ") + "composite desirability (predictable responses) " + sc.d.toFixed(2);
  } else { ov.textContent = ""; delete ov.dataset.desirability; delete ov.dataset.probability; }
  const side = state.width <= state.height ? "width" : "height", core = state[side] - 2 * D.wall_mm;
  document.getElementById("notes").textContent = solidAt(state) ?
    "at " + sig(state[side], 3) + " mm " + side + " the two " + D.wall_mm + " mm walls leave " + Math.max(core, 0).toFixed(1) + " mm inside, at most one nozzle line: the infill density has no effect, the part prints solid and is predicted at 100 % (the density control is pinned)" : "";
  document.getElementById("maximize").disabled = !Object.keys(weights()).length;
  renderSim();
  document.body.dataset.renders = (+(document.body.dataset.renders || 0) + 1).toString();
}
function runMaximize() {
  const st = document.getElementById("max-status"), t0 = performance.now(), m = maximize();
  if (!m) { st.textContent = "set a goal on a predictable response first"; return; }
  applyDesign(m.best.x);
  const lockedNames = Object.keys(m.fixed), s = m.best.s;
  const cmd = "designer suggest " + R.filter((r) => goals[r.name]).map((r) => "--" + r.quantity + " " + (goals[r.name].kind === "target" ? sig(goals[r.name].value, 6) : goals[r.name].kind)).join(" ") +
    (D.axis === "x" ? "" : " --axis " + D.axis) + F.filter((f) => locked[f.name]).map((f) => " --fix " + f.name + "=" + sig(state[f.name], 6)).join("") +
    (Math.abs(tolerance - 0.1) > 1e-12 ? " --tolerance " + sig(100 * tolerance, 4) : "");
  st.dataset.p = s.p === null ? "" : s.p; st.dataset.d = s.d === null ? "" : s.d; st.dataset.design = JSON.stringify(m.best.x); st.dataset.ms = (performance.now() - t0).toFixed(0);
  st.textContent = "best of " + m.searched + " level combination(s) \u00d7 " + m.starts + " starts" + (lockedNames.length ? ", holding " + lockedNames.join(", ") : "") + ": " +
    (s.p === null ? "" : "P " + (100 * s.p).toFixed(1) + " %, ") + "D " + s.d.toFixed(3) + " at " + designText(m.best.x, solidAt(m.best.x) ? ["density"] : []) + ". The same search as: " + cmd;
}
document.getElementById("source").textContent = "surrogate " + D.surrogate_id + "; " + D.runs.density.length +
  " measured runs (points: runs whose other factors lie within " + (100 * NEAR) + " % of their range of the sliders, same layer and raster); shaded: 95 % prediction interval; dashed: target, band \u00b1 the tolerance. Click or drag inside a panel to set its factor.";
const tolEl = document.getElementById("tolerance");
tolEl.value = sig(100 * tolerance, 4);
tolEl.setAttribute("aria-label", "tolerance around a target, \u00b1 %");
tolEl.oninput = () => { const v = parseFloat(tolEl.value); if (v > 0 && v < 100) { tolerance = v / 100; render(); } };
document.getElementById("maximize").onclick = runMaximize;
document.getElementById("remember").onclick = remember;
document.getElementById("copy-json").onclick = () => copyText(suggestionJson());
document.getElementById("forget").onclick = () => { memory = []; saveMemory(); };
buildControls(); buildSuggestions(); buildRows(); buildNoise(); panelEvents(); renderMemory(); render();
document.body.dataset.ready = performance.now().toFixed(1);
