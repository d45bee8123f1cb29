// ---- goals set on the page: typed numbers read strictly, errors shown beside their box ----
const goalError = {}; // response name -> the message shown beside its goal, or absent
const reachCache = {}; // response name -> { key, range }: the predicted range over the search box
// a number as typed: digits with a decimal point and an optional exponent; a comma is named, never misread;
// `example` is a number the box takes, for the message
function parseTyped(text, example = "0.8") {
  const t = String(text).trim();
  if (t === "") return { error: "empty: type a number" };
  if (/^[+-]?\d*,\d+$/.test(t)) return { error: "'" + t + "' has a comma: write the decimal point as '.' (" + t.replace(",", ".") + ")" };
  if (!/^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$/.test(t)) return { error: "'" + t + "' is not a number: type e.g. " + example };
  return { value: parseFloat(t) };
}
// a goal number of response r as designer.design.targets.make_target accepts it: positive (a low limit
// may be 0), finite, at most a million times the largest measured
function goalNumber(r, text, what, zeroOk) {
  const n = parseTyped(text);
  if (n.error) return { error: what + ": " + n.error };
  const v = n.value;
  if (!isFinite(v) || (zeroOk ? v < 0 : v <= 0)) return { error: what + " " + sig(v, 6) + " " + r.unit + " must be " + (zeroOk ? "0 or more" : "positive") + ": give a value > 0" };
  if (v > 1e6 * r.observed[1]) return { error: what + " " + sig(v, 6) + " " + r.unit + " is over a million times the largest measured, " + sig(r.observed[1], 3) + " " + r.unit };
  return { value: v };
}
const GOAL_KINDS = (r) => (r.predictable ? ["none", "target", "limits", "min", "max"] : ["none", "target", "limits"]);
function goalRow(r) {
  const g = r.target, kind = g ? g.kind : "none", box = (id, label, v) =>
    '<input type="text" inputmode="decimal" class="num" id="' + id + '" aria-label="' + esc(label) + '" aria-describedby="goal-err-' + r.name + '" value="' + esc(v) + '">';
  return '<div class="goalrow" id="goal-row-' + r.name + '"><label class="gname" for="goal-kind-' + r.name + '">' + esc(r.name) + (r.predictable ? "" : " (not predictable)") + "</label>" +
    '<select id="goal-kind-' + r.name + '" aria-label="goal for ' + r.name + '">' +
    GOAL_KINDS(r).map((k) => "<option" + (k === kind ? " selected" : "") + ">" + k + "</option>").join("") + "</select>" +
    '<span class="gv" id="goal-v-' + r.name + '">' + box("goal-value-" + r.name, "target " + r.name + " (" + r.unit + ")", g && g.value !== null ? g.value : "") + "</span>" +
    '<span class="gl" id="goal-l-' + r.name + '">' + box("goal-low-" + r.name, "low limit " + r.name + " (" + r.unit + ")", "") + "<span>to</span>" +
    box("goal-high-" + r.name, "high limit " + r.name + " (" + r.unit + ")", "") + "</span><span>" + esc(r.unit) + "</span>" +
    '<span class="err" id="goal-err-' + r.name + '" role="alert"></span></div>';
}
// read a response's goal controls: the goal, or an error beside the box (and no goal: never the old one)
function readGoal(r) {
  const el = (id) => document.getElementById(id + r.name), kind = el("goal-kind-").value;
  el("goal-v-").hidden = kind !== "target"; el("goal-l-").hidden = kind !== "limits";
  let g = null, err = null, bad = [];
  if (kind === "target") {
    const v = goalNumber(r, el("goal-value-").value, "target", false);
    if (v.error) { err = v.error; bad = ["goal-value-"]; } else g = makeGoal(r, "target", v.value);
  } else if (kind === "limits") {
    const lo = goalNumber(r, el("goal-low-").value, "low limit", true), hi = goalNumber(r, el("goal-high-").value, "high limit", false);
    if (lo.error) { err = lo.error; bad = ["goal-low-"]; }
    else if (hi.error) { err = hi.error; bad = ["goal-high-"]; }
    else if (!(lo.value < hi.value)) { err = "the low limit " + sig(lo.value, 6) + " must be below the high limit " + sig(hi.value, 6) + " " + r.unit; bad = ["goal-low-", "goal-high-"]; }
    else g = makeGoal(r, "limits", null, [lo.value, hi.value]);
  } else g = makeGoal(r, kind);
  for (const id of ["goal-value-", "goal-low-", "goal-high-"]) el(id).setAttribute("aria-invalid", bad.includes(id) ? "true" : "false");
  el("goal-err-").textContent = err || "";
  if (err) goalError[r.name] = err; else delete goalError[r.name];
  goals[r.name] = g;
}
function buildGoals() {
  const box = document.getElementById("goal-rows");
  box.innerHTML = R.map(goalRow).join("");
  for (const r of R) {
    for (const id of ["goal-kind-", "goal-value-", "goal-low-", "goal-high-"]) {
      const e = document.getElementById(id + r.name);
      e[id === "goal-kind-" ? "onchange" : "oninput"] = () => { readGoal(r); render(); };
    }
    readGoal(r);
  }
}
// the goal in words: "within +-10 % of 0.8 N/mm" or "between 0.75 and 0.9 N/mm"
function limitsText(r, g) {
  if (g.kind === "target") return "\u00b1" + sig(100 * tolerance, 3) + " % of " + sig(g.value, 4) + " " + r.unit;
  return sig(g.lsl, 4) + " to " + sig(g.usl, 4) + " " + r.unit;
}
// the predicted range of a predictable response over the search box (cached per set of locked factors)
function reachRange(r) {
  const key = JSON.stringify(searchBox().fixed), c = reachCache[r.name];
  if (!c || c.key !== key) reachCache[r.name] = { key: key, range: predictedRange(r) };
  return reachCache[r.name].range;
}
// designer suggest's hint when a target lies about a unit's thousand from a range (its geometric
// middle): " (a value in N/m rather than N/mm? that is k=0.8 N/mm)", else ""
function slipHint(r, value, range) {
  const ratio = value / Math.sqrt(range[0] * range[1]);
  for (const s of r.slips) {
    if (Math.abs(Math.log10(ratio) - Math.log10(s.ratio)) < Math.log10(s.within))
      return " (" + s.cause + "? that is " + r.quantity + "=" + sig(value * s.multiplier, 6) + " " + r.unit + ")";
  }
  return "";
}
// designer suggest's statement when no design reaches a goal, or null when one does
function outOfReach(r, g) {
  const l = limitsOf(g);
  if (!l || !r.predictable) return null;
  const [lo, hi] = reachRange(r);
  if (l[1] >= lo && l[0] <= hi) return null;
  const held = Object.keys(searchBox().fixed);
  const what = g.kind === "target" ? r.quantity + " = " + sig(g.value, 6) + " " + r.unit + " is out of reach within \u00b1" + sig(100 * tolerance, 3) + " %"
    : r.quantity + " between " + sig(g.lsl, 6) + " and " + sig(g.usl, 6) + " " + r.unit + " is out of reach";
  return what + ": over the tested ranges" + (held.length ? " (holding " + held.join(", ") + ")" : "") + " the surrogate predicts " + r.name + " from " + sig(lo, 3) + " to " + sig(hi, 3) + " " + r.unit +
    (g.kind === "target" ? slipHint(r, g.value, r.observed) : "");
}
function goalText(r, p, prob) {
  const g = goals[r.name];
  if (goalError[r.name]) return "no goal: " + goalError[r.name];
  if (!g) return "";
  if (g.kind === "target" && toleranceError) return "no P: " + toleranceError;
  if (!r.predictable && r.calibrated && limitsOf(g))
    return "P(" + limitsText(r, g) + ") = " + pct(prob) + " here: your prints pin " + r.name + " down near the designs you printed (not predictable from the six factors elsewhere; maximize does not act on it)";
  if (!r.predictable) {
    if (!limitsOf(g)) return "goal " + g.kind + ": cannot be acted on, no setting changes it";
    const hint = g.kind === "target" && (g.value < p.low || g.value > p.high) ? slipHint(r, g.value, [p.low, p.high]) : "";
    return r.name + " is not predictable: any design lands within " + limitsText(r, g) + hint + " with probability " + prob.toFixed(2) + "; no setting can be chosen for it from this data";
  }
  const d = desirability(g, p.value);
  if (!limitsOf(g)) return g.kind + " (desirability bounds " + sig(g.low, 3) + " to " + sig(g.high, 3) + " " + r.unit + "): desirability " + d.toFixed(2);
  const out = outOfReach(r, g);
  return (out ? out + ". " : "") + "P(" + limitsText(r, g) + ") = " + pct(prob) + ", desirability " + d.toFixed(2);
}
// a probability in per cent: one decimal below 10 %, none above
function pct(p) { return (100 * p).toFixed(p < 0.1 ? 1 : 0) + " %"; }
// the goal as the suggestion file records it: a number, "min", "max", "limits" or null
function goalKey(g) { return !g ? null : g.kind === "target" ? g.value : g.kind; }
// a suggestion found with another surrogate, or for other goals (or another tolerance) than the
// page's now: greyed, and says so
function suggestionStale() {
  const sg = D.suggestion_goals;
  if (!sg) return null;
  if (sg.surrogate_id && sg.surrogate_id !== D.surrogate_id)
    return "found with surrogate " + sg.surrogate_id + ", not this page's " + D.surrogate_id + ": its P is not this surrogate's";
  const diff = [];
  for (const r of R) {
    if (!r.predictable) continue;
    const was = sg.targets[r.quantity] === undefined ? null : sg.targets[r.quantity], now = goalKey(goals[r.name]);
    const same = typeof was === "number" && typeof now === "number" ? Math.abs(was - now) <= 1e-9 * Math.abs(was) : was === now;
    if (!same) diff.push(r.quantity);
  }
  const anyTarget = R.some((r) => r.predictable && typeof sg.targets[r.quantity] === "number");
  if (anyTarget && Math.abs(sg.tolerance - tolerance) > 1e-12) diff.push("tolerance");
  if (!diff.length) return null;
  const was = R.filter((r) => r.predictable && sg.targets[r.quantity] !== null && sg.targets[r.quantity] !== undefined)
    .map((r) => r.quantity + " " + (typeof sg.targets[r.quantity] === "number" ? "= " + sg.targets[r.quantity] + " " + r.unit + " \u00b1" + sig(100 * sg.tolerance, 3) + " %" : sg.targets[r.quantity]));
  return "found for an earlier goal (" + (was.length ? was.join(", ") : "none") + "): its P is not for the goal now";
}
