// ---- maximize: designer suggest's search (designer/suggestions.py _search and _rank), in the page ----
// The same cost (squared miss of a target, the value itself for min or max, a small term on the PI
// width), the same starts per categorical combination, a box-constrained Newton method in place of
// IPOPT, the same rounding to printable values and the same ranking: P, then D, then the narrower k PI.
function weights() {
  const w = {};
  for (const r of R) {
    const t = goals[r.name];
    if (!t || !r.predictable) continue;
    const scale = t.high - t.low, e = { goal: 1, wsq: 0, wlin: 0, wpi: D.search.pi_weight * t.importance / (scale * scale) };
    if (t.value !== null) { e.goal = t.value; e.wsq = t.importance / (scale * scale); }
    else e.wlin = (t.kind === "min" ? 1 : -1) * t.importance / scale;
    w[r.name] = e;
  }
  return w;
}
function roundPrintable(x) {
  const out = Object.assign({}, x);
  for (const f of FC) out[f.name] = Number((Math.round(out[f.name] / f.step) * f.step).toFixed(6));
  return out;
}
function isclose(a, b) { return Math.abs(a - b) <= 1e-8 + 1e-5 * Math.abs(b); }
function combos(fixed) {
  let out = [[]];
  for (const f of FK) out = out.flatMap((c) => f.levels.map((lv) => c.concat([lv])));
  return out.filter((c) => FK.every((f, i) => !(f.name in fixed) || isclose(fixed[f.name], c[i])));
}
// minimise fun over lb <= u <= ub: projected Newton, derivatives by central differences
function minimize(fun, u0, lb, ub) {
  const n = u0.length, free = [], h = 1e-6, hh = 1e-4;
  for (let i = 0; i < n; i++) if (ub[i] > lb[i]) free.push(i);
  const clip = (v) => v.map((x, i) => Math.min(ub[i], Math.max(lb[i], x)));
  const at = (v, i, d) => { const a = v.slice(); a[i] += d; return a; };
  let u = clip(u0), fu = fun(u);
  for (let it = 0; it < 200 && free.length; it++) {
    const g = new Array(n).fill(0);
    for (const i of free) g[i] = (fun(at(u, i, h)) - fun(at(u, i, -h))) / (2 * h);
    let pg = 0;
    for (const i of free) pg = Math.max(pg, Math.abs(Math.min(ub[i], Math.max(lb[i], u[i] - g[i])) - u[i]));
    if (pg < 1e-11) break;
    const act = free.filter((i) => !((u[i] <= lb[i] && g[i] > 0) || (u[i] >= ub[i] && g[i] < 0)));
    const m = act.length, H = act.map(() => new Array(m).fill(0));
    for (let a = 0; a < m; a++) {
      const i = act[a];
      H[a][a] = (fun(at(u, i, hh)) - 2 * fu + fun(at(u, i, -hh))) / (hh * hh);
      for (let b = 0; b < a; b++) {
        const j = act[b], pp = at(at(u, i, hh), j, hh), pm = at(at(u, i, hh), j, -hh), mp = at(at(u, i, -hh), j, hh), mm = at(at(u, i, -hh), j, -hh);
        H[a][b] = H[b][a] = (fun(pp) - fun(pm) - fun(mp) + fun(mm)) / (4 * hh * hh);
      }
    }
    const step = newtonStep(H, act.map((i) => -g[i]));
    let t = 1, moved = false;
    for (let k = 0; k < 50; k++) {
      const v = u.slice();
      act.forEach((i, a) => { v[i] += t * step[a]; });
      const w = clip(v), fw = fun(w);
      let dec = 0;
      for (let i = 0; i < n; i++) dec += g[i] * (w[i] - u[i]);
      if (fw <= fu + 1e-4 * dec && fw <= fu) {
        const dmax = Math.max(...w.map((x, i) => Math.abs(x - u[i])));
        moved = dmax > 1e-13; u = w; fu = fw;
        break;
      }
      t *= 0.5;
    }
    if (!moved) break;
  }
  return u;
}
// (H + lambda I) s = rhs with lambda raised until the Cholesky factorisation succeeds
function newtonStep(H, rhs) {
  const m = rhs.length;
  let lam = 0;
  const scale = Math.max(1e-12, ...H.map((row, i) => Math.abs(row[i])));
  for (let k = 0; k < 60; k++) {
    const L = cholesky(H.map((row, i) => row.map((v, j) => v + (i === j ? lam : 0))));
    if (L) {
      const y = new Array(m), s = new Array(m);
      for (let i = 0; i < m; i++) { let v = rhs[i]; for (let j = 0; j < i; j++) v -= L[i][j] * y[j]; y[i] = v / L[i][i]; }
      for (let i = m - 1; i >= 0; i--) { let v = y[i]; for (let j = i + 1; j < m; j++) v -= L[j][i] * s[j]; s[i] = v / L[i][i]; }
      return s;
    }
    lam = lam ? lam * 10 : 1e-8 * scale;
  }
  return rhs;
}
function cholesky(A) {
  const m = A.length, L = A.map(() => new Array(m).fill(0));
  for (let i = 0; i < m; i++) for (let j = 0; j <= i; j++) {
    let s = A[i][j];
    for (let k = 0; k < j; k++) s -= L[i][k] * L[j][k];
    if (i === j) { if (!(s > 0)) return null; L[i][i] = Math.sqrt(s); } else L[i][j] = s / L[j][j];
  }
  return L;
}
// the search box: the locked factors held (density at 100 % where a locked width or height is solid),
// the rest over their tested ranges in coded units u in [0, 1]
function searchBox() {
  const names = FC.map((f) => f.name), fixed = {};
  for (const f of F) if (locked[f.name]) fixed[f.name] = state[f.name];
  const thin = ["width", "height"].some((n) => n in fixed && fixed[n] - 2 * D.wall_mm <= D.nozzle_mm + 1e-9);
  if (thin) fixed.density = 100;
  const lows = FC.map((f) => f.low), spans = FC.map((f) => f.high - f.low), lb = names.map(() => 0), ub = names.map(() => 1);
  names.forEach((n, i) => { if (n in fixed) lb[i] = ub[i] = (fixed[n] - lows[i]) / spans[i]; });
  const design = (u, combo) => {
    const x = {};
    names.forEach((n, i) => { x[n] = lows[i] + spans[i] * u[i]; });
    FK.forEach((f, i) => { x[f.name] = combo[i]; });
    return x;
  };
  return { names: names, fixed: fixed, lows: lows, spans: spans, lb: lb, ub: ub, combos: combos(fixed), design: design };
}
// smallest and largest predicted value of a response over the search box, as designer.design.search's
// reachable_range finds them (per level combination, from the box's centre; each extreme as printed),
// widened by the search's starts
function predictedRange(r) {
  const b = searchBox(), values = [];
  for (const combo of b.combos) for (const sign of [1, -1]) {
    const cost = (u) => sign * predictRaw(r, b.design(u, combo)).value;
    for (const u0 of [b.names.map(() => 0.5)].concat(D.search.starts.slice(0, 2)))
      values.push(predict(r, b.design(minimize(cost, u0, b.lb, b.ub), combo)).value);
  }
  return [Math.min(...values), Math.max(...values)];
}
function maximize() {
  const w = weights(), b = searchBox(), { names, fixed, lows, spans, lb, ub } = b;
  if (!Object.keys(w).length) return null;
  const iw = names.indexOf("width"), id = names.indexOf("density"), slb = lb.slice(), sub = ub.slice();
  slb[iw] = sub[iw] = (2 * D.wall_mm + D.nozzle_mm - lows[iw]) / spans[iw];
  slb[id] = sub[id] = (100 - lows[id]) / spans[id];
  const maybeSolid = !("width" in fixed) && !("density" in fixed) && slb[iw] >= 0 && slb[iw] <= 1;
  const held = {};
  for (const n of names) if (n in fixed) held[n] = fixed[n];
  const cs = b.combos, starts = D.search.starts.slice(0, Math.max(2, Math.ceil(D.search.n_starts / cs.length)));
  const raw = [];
  for (const combo of cs) {
    const design = (u) => b.design(u, combo);
    const cost = (u) => {
      const x = design(u);
      let c = 0;
      for (const r of R) {
        const e = w[r.name];
        if (!e) continue;
        const y = predictRaw(r, x);
        c += e.wsq * (y.value - e.goal) ** 2 + e.wlin * y.value + e.wpi * (y.high - y.low) ** 2;
      }
      return c;
    };
    const found = starts.map((u0) => design(minimize(cost, u0, lb, ub)));
    if (maybeSolid && found.some((x) => solidAt(roundPrintable(x))))
      found.push(design(minimize(cost, names.map(() => 0.5), slb, sub)));
    for (const x of found) {
      const d = roundPrintable(Object.assign(x, held));
      raw.push(solidAt(d) ? Object.assign(d, { density: 100 }) : d);
    }
  }
  const k = R.find((r) => r.quantity === "k");
  const ranked = raw.map((x) => ({ x: x, s: score(x) })).map((c) => Object.assign(c, {
    key: [-(c.s.p || 0), -(c.s.d || 0), k ? Math.log(c.s.pred[k.name].high / c.s.pred[k.name].low) : 0] }));
  ranked.sort((a, b) => a.key[0] - b.key[0] || a.key[1] - b.key[1] || a.key[2] - b.key[2]);
  return { best: ranked[0], fixed: fixed, searched: cs.length, starts: starts.length };
}
