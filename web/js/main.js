// The explorer page: the case editor, the diagram in Z (the paper's Fig. 2), the orbit of a
// clicked point, the regime map, the exports, and the test hook `?case=NAME&report=1` (the
// approach diagram of the built-in case NAME, its special points as `drumroll continue --json`
// gives them written into the element #report).
import { Compute } from "./compute.js";
import { CaseForm, readNumber } from "./case_form.js";
import { drawPlot } from "./plot.js";

const APPROACH = "#1f5fbf";
const RETRACT = "#c2410c";
const PALETTE = ["#1f5fbf", "#c2410c", "#2e7d32", "#6a1b9a", "#00838f", "#ad1457", "#5d4037", "#455a64"];

const $ = (id) => document.getElementById(id);
const compute = new Compute();
const state = {
  catalogue: null,
  catalogueCase: null,
  diagram: null,
  picked: null,
  orbit: null,
  requestedAt: 0,
};
// Timings and counters for the browser tests (web/tests) and the curious.
window.drumroll = {
  diagramsDrawn: 0, firstDiagramMs: null, lastDiagramMs: null, lastComputeMs: null, orbitsDrawn: 0, mapsDrawn: 0,
  /** The text an export button downloads (`diagram_csv`, `map_svg`, ...). */
  exportText: async (method) => (await compute.call(method)).value,
};

function showError(message) {
  const box = $("error");
  box.textContent = message;
  box.hidden = !message;
}

function showWarnings(warnings) {
  $("warnings").replaceChildren(...warnings.map((w) => Object.assign(document.createElement("li"), { textContent: w })));
}

function status(text) {
  $("status").textContent = text;
}

/** The built-in case `name` of the catalogue, or undefined. */
function catalogueEntry(name) {
  return state.catalogue.cases.find((c) => c.name === name);
}

function selectCase(name) {
  const entry = catalogueEntry(name);
  $("case-select").value = name;
  $("case-description").textContent = entry.description;
  state.catalogueCase = entry.case;
  form.show(entry.case);
  const a0 = entry.case.free_amplitude_nm;
  const slider = $("a0-slider");
  slider.min = String(Math.max(0.1, a0 / 10));
  slider.max = String(a0 * 5);
  slider.step = String(a0 / 100);
  slider.value = String(a0);
  fillMapForm();
}

/** The continuation's options of the form. */
function diagramOptions() {
  const options = {
    min_amplitude_ratio: readNumber($("min-ratio")),
    retract: $("retract").checked,
  };
  const floor = readNumber($("floor"), { optional: true });
  if (floor !== null) options.floor_nm = floor;
  const step = readNumber($("max-step"), { optional: true });
  if (step !== null) options.max_step_nm = step;
  return options;
}

/** JSON text of `value` with every object's keys sorted (`null` and absent keys alike). */
function canonical(value) {
  if (Array.isArray(value)) return `[${value.map(canonical).join(",")}]`;
  if (value && typeof value === "object") {
    const keys = Object.keys(value).filter((k) => value[k] !== null && value[k] !== undefined).sort();
    return `{${keys.map((k) => `${JSON.stringify(k)}:${canonical(value[k])}`).join(",")}}`;
  }
  return JSON.stringify(value);
}

/** The edited case; renamed `NAME-edited` once it differs from the built-in case. */
function editedCase() {
  const edited = form.read();
  const base = state.catalogueCase;
  const same = canonical({ ...edited, name: base.name, description: base.description }) === canonical(base);
  if (!same) edited.name = `${base.name}-edited`;
  return edited;
}

/** Recompute the diagram of the form (latest wins while one is running). */
async function recompute() {
  let request;
  try {
    request = { case: editedCase(), ...diagramOptions() };
  } catch (error) {
    showError(error.message);
    return;
  }
  await computeDiagram(request);
}

async function computeDiagram(request) {
  state.requestedAt = performance.now();
  const requestedAt = state.requestedAt;
  status("computing the diagram\u2026");
  let reply;
  try {
    reply = await compute.latest("diagram", "diagram", JSON.stringify(request));
  } catch (error) {
    showError(error.message);
    status("");
    return false;
  }
  if (reply === null) return null; // superseded by a newer request
  const result = JSON.parse(reply.value);
  showError("");
  showWarnings(result.warnings);
  state.diagram = result.diagram;
  state.picked = null;
  $("orbit").hidden = true;
  drawDiagram();
  renderSpecialPoints();
  const now = performance.now();
  const d = window.drumroll;
  d.diagramsDrawn += 1;
  d.lastComputeMs = reply.ms;
  d.lastDiagramMs = now - requestedAt;
  if (d.firstDiagramMs === null) d.firstDiagramMs = now;
  const points = result.diagram.points.length;
  const stop = result.diagram.completed ? "" : ` (stopped early: ${result.diagram.stop}${result.diagram.error ? `: ${result.diagram.error}` : ""})`;
  status(`${result.diagram.case}: ${points} branch points, ${result.diagram.special_points.length} special points, computed in ${reply.ms.toFixed(0)} ms${stop}`);
  return true;
}

/** Runs of consecutive points with the same stability, each with the next run's first point. */
function stabilityRuns(points, x, y) {
  const runs = [];
  let current = null;
  points.forEach((p, i) => {
    if (!current || current.stable !== p.stable) {
      if (current) current.points.push([x(p), y(p)]);
      current = { stable: p.stable, points: [] };
      runs.push(current);
    }
    current.points.push([x(p), y(p)]);
  });
  return runs;
}

function markerColour(label) {
  if (label.startsWith("G")) return "#2e7d32";
  if (label === "fold") return "#b3261e";
  return "#6a1b9a";
}

function drawDiagram() {
  const diagram = state.diagram;
  const branches = [{ name: "approach", points: diagram.points, special: diagram.special_points, colour: APPROACH }];
  if (diagram.retract) branches.push({ name: "retract", points: diagram.retract.points, special: diagram.retract.special_points, colour: RETRACT });
  const panels = [
    ["plot-phase-ratio", "phase vs amplitude (Fig. 2)", (p) => p.amplitude_ratio, (p) => p.phase_deg, "A/A0", "phase (deg)"],
    ["plot-ratio-z", "amplitude vs separation", (p) => p.z_nm, (p) => p.amplitude_ratio, "Z (nm)", "A/A0"],
    ["plot-phase-z", "phase vs separation", (p) => p.z_nm, (p) => p.phase_deg, "Z (nm)", "phase (deg)"],
  ];
  for (const [id, title, x, y, xLabel, yLabel] of panels) {
    const series = branches.flatMap((b) => stabilityRuns(b.points, x, y).map((run) => ({ points: run.points, colour: b.colour, dashed: !run.stable })));
    const markers = branches.flatMap((b) => b.special.map((s) => ({ x: x(s), y: y(s), label: s.label, colour: markerColour(s.label) })));
    const pickable = branches.flatMap((b) => b.points.map((p, index) => [x(p), y(p), { branch: b.name, index }]));
    const picked = state.picked ? branchPoint(state.picked) : null;
    drawPlot($(id), {
      title: branches.length > 1 ? `${title}: approach blue, retract orange` : title,
      xLabel, yLabel, series, markers, pickable,
      picked: picked ? { x: x(picked), y: y(picked) } : null,
      onPick: pickPoint,
    });
  }
}

function branchPoint({ branch, index }) {
  const points = branch === "retract" ? state.diagram.retract.points : state.diagram.points;
  return points[index];
}

function renderSpecialPoints() {
  const body = document.querySelector("#special-points tbody");
  body.replaceChildren();
  const rows = state.diagram.special_points.map((s) => ["", s]);
  if (state.diagram.retract) rows.push(...state.diagram.retract.special_points.map((s) => ["retract ", s]));
  for (const [prefix, s] of rows) {
    const row = body.insertRow();
    const cells = [prefix + s.label, s.z_nm.toFixed(10), s.amplitude_ratio.toFixed(6), s.phase_deg.toFixed(4),
      `${s.impacts_before} \u2192 ${s.impacts_after}`, s.precision_nm.toExponential(1), s.converged ? "yes" : "NO"];
    for (const text of cells) row.insertCell().textContent = text;
  }
}

async function pickPoint(pick) {
  state.picked = pick;
  drawDiagram();
  const point = branchPoint(pick);
  status(`computing the orbit at Z = ${point.z_nm.toFixed(4)} nm\u2026`);
  let reply;
  try {
    reply = await compute.latest("orbit", "orbit", JSON.stringify({ z_nm: point.z_nm, state: point.state }));
  } catch (error) {
    showError(error.message);
    return;
  }
  if (reply === null) return;
  showError("");
  const result = JSON.parse(reply.value);
  drawOrbit(result);
  window.drumroll.orbitsDrawn += 1;
  status(`orbit at Z = ${result.orbit.z_nm.toFixed(6)} nm computed in ${reply.ms.toFixed(0)} ms`);
}

function drawOrbit({ orbit, trajectory }) {
  $("orbit").hidden = false;
  $("orbit-title").textContent = `Orbit at Z = ${orbit.z_nm.toFixed(6)} nm (${orbit.stable ? "stable" : "unstable"}, period ${orbit.multiplicity})`;
  const t = trajectory.t_periods;
  const periods = t[t.length - 1];
  const shades = [];
  for (let k = 0; k * orbit.multiplicity < periods; k++) {
    for (const impact of orbit.impacts) {
      shades.push({ x0: impact.start_periods + k * orbit.multiplicity, x1: impact.end_periods + k * orbit.multiplicity });
    }
  }
  const series = (values) => [{ points: t.map((x, i) => [x, values[i]]), colour: APPROACH }];
  const xLabel = "time t / T (drive periods)";
  drawPlot($("plot-u"), { title: "photodiode signal u(t); impacts shaded", xLabel, yLabel: "u (nm)", series: series(trajectory.u_nm), shades });
  drawPlot($("plot-force"), { title: "tip-sample force F_ts(t)", xLabel, yLabel: "F_ts (nN)", series: series(trajectory.force_nn), shades });
  const gapSeries = series(trajectory.gap_nm);
  gapSeries.push({ points: [[0, 0], [periods, 0]], colour: "#888", dashed: true });
  drawPlot($("plot-gap"), { title: "gap d(t) = Z + sum q_i (contact below 0)", xLabel, yLabel: "d (nm)", series: gapSeries, shades });
  const rows = [
    ["Z (nm)", orbit.z_nm.toFixed(9)],
    ["A/A0", orbit.amplitude_ratio.toFixed(6)],
    ["phase (deg)", orbit.phase_deg.toFixed(4)],
    ["impacts per period", String(orbit.impacts_per_period)],
    ["period (drive periods)", String(orbit.multiplicity)],
    ["stable", orbit.stable ? "yes" : "no"],
    ["largest |Floquet multiplier|", orbit.spectral_radius.toExponential(3)],
    ["lowest gap (nm)", orbit.min_gap_nm === null ? "none" : orbit.min_gap_nm.toExponential(4)],
    ["peak force (nN)", orbit.peak_force_nn.toFixed(6)],
    ["mean force (nN)", orbit.mean_force_nn.toExponential(4)],
    ["contact time (periods per period)", orbit.contact_time_periods.toFixed(6)],
    ["impulse per period (nN us)", orbit.impulse_nn_us.toFixed(6)],
    ["converged (residual)", `${orbit.converged ? "yes" : "NO"} (${orbit.residual.toExponential(1)})`],
  ];
  orbit.impacts.forEach((impact, i) => rows.push([`impact ${i + 1}: t / T, onset speed, peak`,
    `${impact.start_periods.toFixed(4)} .. ${impact.end_periods.toFixed(4)}, ${impact.velocity_nm_per_us.toFixed(4)} nm/us, ${impact.peak_force_nn.toFixed(4)} nN`]));
  const body = document.querySelector("#observables tbody");
  body.replaceChildren();
  for (const [name, value] of rows) {
    const row = body.insertRow();
    row.appendChild(Object.assign(document.createElement("th"), { textContent: name }));
    row.insertCell().textContent = value;
  }
}

// The regime map.

function fillMapForm() {
  const modes = state.catalogueCase.cantilever.modes.length;
  const names = state.catalogue.parameters.flatMap((name) => name.endsWith("-N")
    ? Array.from({ length: modes }, (_, i) => name.replace(/N$/, String(i + 1)))
    : [name]);
  const select = $("map-vary");
  const previous = select.value;
  select.replaceChildren(...names.map((n) => new Option(n, n)));
  select.value = names.includes(previous) ? previous : "a0";
  setMapRange();
}

/** The map's default range: the case's own value of the parameter, halved and doubled. */
function setMapRange() {
  const c = state.catalogueCase;
  const vary = $("map-vary").value;
  const mode = Number(vary.split("-").pop()) - 1;
  const value = {
    a0: c.free_amplitude_nm,
    "drive-frequency": c.drive_frequency_khz ?? c.cantilever.modes[0].frequency_khz,
    "sample-modulus": c.sample.youngs_modulus_gpa,
    "tip-radius": c.cantilever.tip_radius_nm,
  }[vary] ?? (vary.startsWith("quality-factor") ? c.cantilever.modes[mode].quality_factor : c.cantilever.modes[mode]?.stiffness_n_per_m);
  const narrow = vary === "drive-frequency";
  $("map-from").value = String(Number((value * (narrow ? 0.9 : 0.5)).toPrecision(4)));
  $("map-to").value = String(Number((value * (narrow ? 1.1 : 2)).toPrecision(4)));
}

async function computeMap(event) {
  event.preventDefault();
  let request;
  try {
    request = {
      case: editedCase(),
      ...diagramOptions(),
      vary: $("map-vary").value,
      from: readNumber($("map-from")),
      to: readNumber($("map-to")),
      points: readNumber($("map-points")),
      labels: $("map-labels").value.split(",").map((s) => s.trim()).filter((s) => s),
    };
    delete request.retract;
  } catch (error) {
    showError(error.message);
    return;
  }
  status("computing the regime map (each curve is a continuation in two parameters)\u2026");
  let reply;
  try {
    reply = await compute.latest("map", "map", JSON.stringify(request));
  } catch (error) {
    showError(error.message);
    status("");
    return;
  }
  if (reply === null) return;
  showError("");
  const map = JSON.parse(reply.value);
  const unit = map.parameter.unit ? ` (${map.parameter.unit})` : "";
  const xLabel = `${map.parameter.name}${unit}`;
  for (const [id, key, yLabel] of [["plot-map-z", "z_nm", "Z (nm)"], ["plot-map-ratio", "amplitude_ratio", "A/A0"]]) {
    const series = map.curves.flatMap((curve, i) => stabilityRuns(curve.points, (p) => p.parameter, (p) => p[key])
      .map((run) => ({ points: run.points, colour: PALETTE[i % PALETTE.length], dashed: !run.stable })));
    const markers = map.curves.map((curve, i) => {
      const middle = curve.points[Math.floor(curve.points.length / 2)];
      return middle ? { x: middle.parameter, y: middle[key], label: curve.label, colour: PALETTE[i % PALETTE.length] } : null;
    }).filter((m) => m).concat(map.codim2_points.map((p) => ({ x: p.parameter, y: key === "z_nm" ? p.z_nm : p.amplitude_ratio, label: p.label, colour: "#222" })));
    drawPlot($(id), { title: `${map.case}: ${yLabel} of the special points`, xLabel, yLabel, series, markers });
  }
  window.drumroll.mapsDrawn += 1;
  status(`regime map: ${map.curves.length} curves, ${map.codim2_points.length} codimension-two points, computed in ${(reply.ms / 1000).toFixed(1)} s`);
}

// Exports: the module's text, as the command line writes it.

const EXPORTS = {
  diagram_json: ["diagram.json", "application/json"],
  diagram_csv: ["diagram.csv", "text/csv"],
  diagram_svg: ["diagram.svg", "image/svg+xml"],
  orbit_json: ["orbit.json", "application/json"],
  orbit_svg: ["orbit.svg", "image/svg+xml"],
  map_json: ["map.json", "application/json"],
  map_csv: ["map.csv", "text/csv"],
  map_svg: ["map.svg", "image/svg+xml"],
};

async function exportFile(method) {
  try {
    const { value } = await compute.call(method);
    const [suffix, type] = EXPORTS[method];
    const link = document.createElement("a");
    link.href = URL.createObjectURL(new Blob([value], { type }));
    link.download = `${state.diagram?.case ?? "drumroll"}-${suffix}`;
    link.click();
    setTimeout(() => URL.revokeObjectURL(link.href), 10_000);
  } catch (error) {
    showError(error.message);
  }
}

// Wiring.

const form = new CaseForm(recompute);

async function main() {
  const params = new URLSearchParams(location.search);
  try {
    state.catalogue = JSON.parse((await compute.call("catalogue")).value);
  } catch (error) {
    showError(`The computing module did not load: ${error.message}`);
    status("");
    if (params.get("report") === "1") {
      $("report").hidden = false;
      $("report").textContent = JSON.stringify({ error: $("error").textContent });
    }
    return;
  }
  const select = $("case-select");
  for (const entry of state.catalogue.cases) select.add(new Option(entry.name, entry.name));
  select.addEventListener("change", () => {
    selectCase(select.value);
    recompute();
  });
  $("a0-slider").addEventListener("input", (event) => {
    $("a0").value = event.target.value;
    recompute();
  });
  $("a0").addEventListener("change", () => {
    const value = Number($("a0").value);
    if (Number.isFinite(value)) $("a0-slider").value = String(value);
  });
  for (const id of ["floor", "min-ratio", "max-step", "retract"]) $(id).addEventListener("change", recompute);
  for (const button of document.querySelectorAll("[data-export]")) {
    button.addEventListener("click", () => exportFile(button.dataset.export));
  }
  for (const tab of document.querySelectorAll("nav [role=tab]")) {
    tab.addEventListener("click", () => {
      for (const other of document.querySelectorAll("nav [role=tab]")) {
        other.setAttribute("aria-selected", String(other === tab));
        $(other.dataset.panel).hidden = other !== tab;
      }
    });
  }
  $("map-vary").addEventListener("change", setMapRange);
  $("map-form").addEventListener("submit", computeMap);

  const named = params.get("case");
  const known = named && catalogueEntry(named);
  selectCase(known ? named : state.catalogue.default_case);
  if (params.get("report") === "1") {
    // The test hook: the built-in case by name, exactly as `drumroll continue --case NAME`.
    const report = $("report");
    report.hidden = false;
    const done = await computeDiagram({ case: { name: named ?? state.catalogue.default_case } });
    if (done) {
      report.textContent = (await compute.call("special_points")).value;
    } else {
      report.textContent = JSON.stringify({ error: $("error").textContent });
    }
    return;
  }
  if (named && !known) showError(`case ${named}: no such built-in case (the list shows them)`);
  await recompute();
}

main();
