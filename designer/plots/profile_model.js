"use strict";
const D = JSON.parse(document.getElementById("data").textContent);
const F = D.factors, R = D.responses, FC = F.filter((f) => !f.categorical), FK = F.filter((f) => f.categorical);
const state = Object.assign({}, D.design), locked = {}, goals = {};
let tolerance = D.tolerance;
let toleranceError = null; // the tolerance box's error: no target has limits (nor a P) until it is fixed
for (const r of R) goals[r.name] = r.target ? Object.assign({}, r.target) : null;
const NEAR = 0.25; // a run is near when its other factors lie within this share of their range
const CURVE = 41; // points on each continuous panel's curve

// ---- the surrogate, computed as designer.model.prediction's ResponseSurface.predict does ----
function ev(n, x) {
  switch (n[0]) {
    case "x": return x[n[1]];
    case "c": return n[1];
    case "+": return ev(n[1], x) + ev(n[2], x);
    case "-": return ev(n[1], x) - ev(n[2], x);
    case "*": return ev(n[1], x) * ev(n[2], x);
    case "/": return ev(n[1], x) / ev(n[2], x);
    case "log": return Math.log(ev(n[1], x));
    case "level": { const a = ev(n[1], x), b = n[2]; return Math.abs(a - b) <= 1e-8 + 1e-5 * Math.abs(b) ? 1 : 0; }
  }
  throw new Error("unknown expression node " + n[0]);
}
function predictRaw(r, x) {
  const z = [1];
  for (const f of r.features) z.push(ev(f, x));
  let mean = 0, q = 0;
  for (let i = 0; i < z.length; i++) mean += z[i] * r.coef[i];
  for (let i = 0; i < z.length; i++) { let s = 0; for (let j = 0; j < z.length; j++) s += r.vcov[i][j] * z[j]; q += z[i] * s; }
  const scale = r.sigma * Math.sqrt(1 + q), half = r.t95 * r.sigma * Math.sqrt(1 + q);
  let v = [mean, mean - half, mean + half];
  const logged = (r.base_transform || r.transform) === "log";
  if (logged) v = v.map(Math.exp);
  if (r.calibration) return calibrated(r, x, v, (name) => slope(r, x, name) / (logged ? 1 : mean));
  return { value: v[0], low: v[1], high: v[2], mean: mean, scale: scale };
}
// as printed (designer.model.forms.as_printed): where the walls fill the section the part is solid
function solidAt(x) { return Math.min(x.width, x.height) - 2 * D.wall_mm <= D.nozzle_mm + 1e-9; }
function asPrinted(x) { return solidAt(x) ? Object.assign({}, x, { density: 100 }) : x; }
function predict(r, x) { return predictRaw(r, asPrinted(x)); }
// d(mean)/d(factor) of the study surface: forward differentiation of its expression trees
function dev(n, x, name) {
  switch (n[0]) {
    case "x": return n[1] === name ? 1 : 0;
    case "c": case "level": return 0;
    case "+": return dev(n[1], x, name) + dev(n[2], x, name);
    case "-": return dev(n[1], x, name) - dev(n[2], x, name);
    case "*": return dev(n[1], x, name) * ev(n[2], x) + ev(n[1], x) * dev(n[2], x, name);
    case "/": { const b = ev(n[2], x); return (dev(n[1], x, name) * b - ev(n[1], x) * dev(n[2], x, name)) / (b * b); }
    case "log": return dev(n[1], x, name) / ev(n[1], x);
  }
  throw new Error("unknown expression node " + n[0]);
}
function slope(r, x, name) {
  let s = 0;
  for (let i = 0; i < r.features.length; i++) s += dev(r.features[i], x, name) * r.coef[i + 1];
  return s;
}
// the printer's mechanism terms at x (designer/model/mechanisms.py): factor, width and height offsets,
// infill exponent, layer adhesion, raster, layer x raster; dmu(name) is d log(study value) / d factor
function mechanismTerms(x, dmu, factors) {
  const coded = (name) => { const [, centre, half] = factors.find((f) => f[0] === name); return (x[name] - centre) / half; };
  const lc = coded("layer"), rs = coded("raster");
  return [1, dmu("width"), dmu("height"), dmu("density") * x.density * Math.log(x.density / 100), lc, rs, lc * rs];
}
// the study's prediction v updated by the user's runs (designer/model/correction.py, log space)
function calibrated(r, x, v, dmu) {
  const c = r.calibration, mu0 = Math.log(v[0]), s0 = (Math.log(v[2]) - mu0) / r.t95;
  const sg0 = Math.sqrt(Math.max(s0 * s0 - c.noise * c.noise, 0.25 * s0 * s0)), sg = c.amplitude * sg0;
  const solid = Math.min(x.width, x.height) - 2 * c.wall <= c.line + 1e-9;
  const z = c.factors.map(([name, centre, half]) => ((name === "density" && solid ? 100 : x[name]) - centre) / half);
  const h = mechanismTerms(x, dmu, c.factors);
  const k = c.runs.map((u, i) => {
    let d2 = 0;
    for (let j = 0; j < z.length; j++) d2 += (z[j] - u[j]) ** 2;
    const m = Math.sqrt(5 * d2) / c.length;  // Matern 5/2 (designer.model.correction.matern52)
    const rho = (1 + m + m * m / 3) * Math.exp(-m);
    let terms = 0;
    for (let t = 0; t < h.length; t++) terms += h[t] * c.hs[i][t];
    return sg * c.sgu[i] * rho + c.local2 * c.own[i] * rho + terms;
  });
  let mu = mu0, q = 0;
  for (let i = 0; i < k.length; i++) {
    mu += k[i] * c.alpha[i];
    let s = 0;
    for (let j = 0; j < k.length; j++) s += c.kinv[i][j] * k[j];
    q += k[i] * s;
  }
  let prior = s0 * s0 + (c.amplitude * c.amplitude - 1) * sg0 * sg0 + c.local2;
  for (let t = 0; t < h.length; t++) prior += c.sb[t] * h[t] * h[t];
  const scale = Math.sqrt(Math.max(prior - q, c.noise * c.noise)), half = r.t95 * scale;
  return { value: Math.exp(mu), low: Math.exp(mu - half), high: Math.exp(mu + half), mean: mu, scale: scale };
}
// ---- Student t distribution (regularised incomplete beta by Lentz's continued fraction) ----
function lgamma(x) {
  const c = [0.99999999999980993, 676.5203681218851, -1259.1392167224028, 771.32342877765313, -176.61502916214059,
    12.507343278686905, -0.13857109526572012, 9.9843695780195716e-6, 1.5056327351493116e-7];
  if (x < 0.5) return Math.log(Math.PI / Math.abs(Math.sin(Math.PI * x))) - lgamma(1 - x);
  x -= 1; let a = c[0]; const t = x + 7.5;
  for (let i = 1; i < 9; i++) a += c[i] / (x + i);
  return 0.5 * Math.log(2 * Math.PI) + (x + 0.5) * Math.log(t) - t + Math.log(a);
}
function betacf(a, b, x) {
  const tiny = 1e-300; let c = 1, d = 1 - (a + b) * x / (a + 1);
  d = 1 / (Math.abs(d) < tiny ? tiny : d); let h = d;
  for (let m = 1; m <= 500; m++) {
    const m2 = 2 * m;
    for (const num of [m * (b - m) * x / ((a + m2 - 1) * (a + m2)), -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1))]) {
      d = 1 + num * d; d = 1 / (Math.abs(d) < tiny ? tiny : d);
      c = 1 + num / c; if (Math.abs(c) < tiny) c = tiny;
      h *= d * c;
      if (num === 0) break;
    }
    if (Math.abs(d * c - 1) < 1e-15) break;
  }
  return h;
}
function ibeta(x, a, b) {
  if (x <= 0) return 0; if (x >= 1) return 1;
  const bt = Math.exp(lgamma(a + b) - lgamma(a) - lgamma(b) + a * Math.log(x) + b * Math.log(1 - x));
  return x < (a + 1) / (a + b + 2) ? bt * betacf(a, b, x) / a : 1 - bt * betacf(b, a, 1 - x) / b;
}
function tcdf(t, nu) {
  const p = 0.5 * ibeta(nu / (nu + t * t), nu / 2, 0.5);
  return t > 0 ? 1 - p : p;
}
// probability that a printed joint lands between two limits (designer.design.targets.probability_between):
// the predictive t distribution in the form's fit space; under the log a lower limit at or below 0 counts as 0
function pBetween(r, p, low, high) {
  const log = r.transform === "log", tr = log ? Math.log : (v) => v;
  const upper = tcdf((tr(high) - p.mean) / p.scale, r.dof);
  const lower = log && low <= 0 ? 0 : tcdf((tr(low) - p.mean) / p.scale, r.dof);
  return Math.max(0, Math.min(1, upper - lower));
}
// the limits a goal is met within: +- the tolerance around a target value, or the goal's own low and high limits
function limitsOf(g) {
  if (!g) return null;
  if (g.kind === "target") return toleranceError ? null : [g.value * (1 - tolerance), g.value * (1 + tolerance)];
  if (g.kind === "limits") return [g.lsl, g.usl];
  return null;
}
// probability that a printed joint meets goal g (null for min and max, which have no limits)
function pGoal(r, p, g) { const l = limitsOf(g); return l ? pBetween(r, p, l[0], l[1]) : null; }
// a goal with its Derringer-Suich bounds, as designer.design.targets.make_target sets them; limits
// [low, high] are a target at their midpoint met between them (the search aims at the midpoint)
function makeGoal(r, kind, value, limits) {
  const [lo, hi] = r.observed;
  if (kind === "none") return null;
  if (kind === "min" || kind === "max") return { kind: kind, value: null, low: lo, high: hi, importance: 1, weight: 1 };
  const v = kind === "limits" ? 0.5 * (limits[0] + limits[1]) : value;
  const g = { kind: kind, value: v, low: Math.min(lo, 0.5 * v), high: Math.max(hi, 1.5 * v), importance: 1, weight: 1 };
  if (kind === "limits") { g.lsl = limits[0]; g.usl = limits[1]; }
  return g;
}
// Derringer-Suich desirability, as designer.design.targets' Target does it
function desirability(t, y) {
  const clip = (v) => Math.min(1, Math.max(0, v));
  if (t.kind === "max") return clip((y - t.low) / (t.high - t.low)) ** t.weight;
  if (t.kind === "min") return clip((t.high - y) / (t.high - t.low)) ** t.weight;
  if (y <= t.low || y >= t.high) return 0;
  return (y <= t.value ? (y - t.low) / (t.value - t.low) : (t.high - y) / (t.high - t.value)) ** t.weight;
}
// how a design meets the goals (designer.design.suggestions.rank): P over the predictable goals with
// limits (what maximize ranks by), the joint P over every stated goal with limits, the predictable and
// the unpredictable alike (the product, as suggest's "every goal at once": given the model the responses
// scatter independently), and the composite desirability D of the predictable responses
function score(x) {
  const pred = {}, prob = {}, ds = [];
  let p = null, joint = null;
  for (const r of R) {
    const y = predict(r, x), g = goals[r.name];
    pred[r.name] = y;
    if (!g) continue;
    const pg = pGoal(r, y, g);
    if (pg !== null) { prob[r.name] = pg; joint = (joint === null ? 1 : joint) * pg; }
    if (!r.predictable) continue;
    ds.push([desirability(g, y.value), g.importance]);
    if (pg !== null) p = (p === null ? 1 : p) * pg;
  }
  const wsum = ds.reduce((a, [, w]) => a + w, 0);
  const d = ds.length ? ds.reduce((a, [v, w]) => a * Math.pow(v, w / wsum), 1) : null;
  return { pred: pred, prob: prob, p: p, joint: joint, d: d };
}
