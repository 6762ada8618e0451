// Small SVG x-y plots drawn in the page (axes with ticks, solid and dashed curves, labelled
// markers, shaded intervals, a picked point), with clicks mapped back to the nearest pickable
// data point. The exported figures are the CLI's own (the module's *_svg), not these.

const NS = "http://www.w3.org/2000/svg";
const MARGIN = { left: 62, right: 14, top: 24, bottom: 40 };

function element(name, attributes, parent) {
  const node = document.createElementNS(NS, name);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
  if (parent) parent.appendChild(node);
  return node;
}

/** About `count` round tick values covering [low, high]. */
export function ticks(low, high, count = 6) {
  if (!(high > low)) return [low];
  const raw = (high - low) / count;
  const power = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 2.5, 5, 10].map((m) => m * power).find((s) => s >= raw) ?? 10 * power;
  const values = [];
  for (let v = Math.ceil(low / step) * step; v <= high + step * 1e-9; v += step) {
    values.push(Math.abs(v) < step * 1e-9 ? 0 : v);
  }
  return values;
}

function format(value) {
  if (value === 0) return "0";
  const magnitude = Math.abs(value);
  if (magnitude >= 1e5 || magnitude < 1e-3) return value.toExponential(1);
  return String(Number(value.toPrecision(6)));
}

/** The [low, high] range of `values` widened by 4 %, or around the value when all are equal. */
function range(values) {
  let low = Infinity;
  let high = -Infinity;
  for (const v of values) {
    if (Number.isFinite(v)) {
      low = Math.min(low, v);
      high = Math.max(high, v);
    }
  }
  if (!Number.isFinite(low)) return [0, 1];
  if (high === low) {
    const pad = Math.abs(low) * 0.1 || 1;
    return [low - pad, high + pad];
  }
  const pad = (high - low) * 0.04;
  return [low - pad, high + pad];
}

/**
 * Draw a plot into `svg` (its viewBox sets the size). `spec`: title, xLabel, yLabel,
 * series [{points: [[x, y]], colour, dashed}], markers [{x, y, label, colour}],
 * shades [{x0, x1}], picked {x, y}, pickable [[x, y, payload]], onPick(payload).
 */
export function drawPlot(svg, spec) {
  const [, , width, height] = svg.getAttribute("viewBox").split(/\s+/).map(Number);
  svg.replaceChildren();
  const series = spec.series ?? [];
  const markers = spec.markers ?? [];
  const xs = series.flatMap((s) => s.points.map((p) => p[0])).concat(markers.map((m) => m.x));
  const ys = series.flatMap((s) => s.points.map((p) => p[1])).concat(markers.map((m) => m.y));
  const [x0, x1] = spec.xRange ?? range(xs);
  const [y0, y1] = spec.yRange ?? range(ys);
  const left = MARGIN.left;
  const right = width - MARGIN.right;
  const top = MARGIN.top;
  const bottom = height - MARGIN.bottom;
  const px = (x) => left + ((x - x0) / (x1 - x0)) * (right - left);
  const py = (y) => bottom - ((y - y0) / (y1 - y0)) * (bottom - top);

  element("text", { x: left, y: 15, class: "title" }, svg).textContent = spec.title ?? "";
  for (const shade of spec.shades ?? []) {
    const a = Math.max(left, px(shade.x0));
    const b = Math.min(right, px(shade.x1));
    if (b > a) element("rect", { x: a, y: top, width: b - a, height: bottom - top, class: "shade" }, svg);
  }
  for (const t of ticks(x0, x1)) {
    element("line", { x1: px(t), x2: px(t), y1: top, y2: bottom, class: "grid" }, svg);
    element("line", { x1: px(t), x2: px(t), y1: bottom, y2: bottom + 4, class: "axis" }, svg);
    element("text", { x: px(t), y: bottom + 15, "text-anchor": "middle" }, svg).textContent = format(t);
  }
  for (const t of ticks(y0, y1, 5)) {
    element("line", { x1: left, x2: right, y1: py(t), y2: py(t), class: "grid" }, svg);
    element("line", { x1: left - 4, x2: left, y1: py(t), y2: py(t), class: "axis" }, svg);
    element("text", { x: left - 6, y: py(t) + 4, "text-anchor": "end" }, svg).textContent = format(t);
  }
  element("rect", { x: left, y: top, width: right - left, height: bottom - top, class: "axis" }, svg);
  element("text", { x: (left + right) / 2, y: height - 6, "text-anchor": "middle" }, svg).textContent = spec.xLabel ?? "";
  element("text", {
    x: 0, y: 0, "text-anchor": "middle",
    transform: `translate(14 ${(top + bottom) / 2}) rotate(-90)`,
  }, svg).textContent = spec.yLabel ?? "";

  const clip = `clip-${svg.id}`;
  const defs = element("defs", {}, svg);
  const clipPath = element("clipPath", { id: clip }, defs);
  element("rect", { x: left, y: top, width: right - left, height: bottom - top }, clipPath);
  const plotArea = element("g", { "clip-path": `url(#${clip})` }, svg);
  for (const s of series) {
    let d = "";
    let pen = "M";
    for (const [x, y] of s.points) {
      if (!Number.isFinite(x) || !Number.isFinite(y)) {
        pen = "M";
        continue;
      }
      d += `${pen}${px(x).toFixed(2)},${py(y).toFixed(2)}`;
      pen = "L";
    }
    if (d) {
      element("path", { d, class: `curve${s.dashed ? " dashed" : ""}`, stroke: s.colour ?? "#1f5fbf" }, plotArea);
    }
  }
  for (const m of markers) {
    if (!Number.isFinite(m.x) || !Number.isFinite(m.y)) continue;
    element("circle", { cx: px(m.x), cy: py(m.y), r: 4, class: "marker", fill: m.colour ?? "#222" }, plotArea);
    const inside = px(m.x) >= left && px(m.x) <= right && py(m.y) >= top && py(m.y) <= bottom;
    if (m.label && inside) {
      // Labels are not clipped: near the right or top edge they go to the left or below.
      const nearRight = px(m.x) > right - 40;
      const nearTop = py(m.y) < top + 14;
      element("text", {
        x: px(m.x) + (nearRight ? -7 : 7),
        y: py(m.y) + (nearTop ? 15 : -7),
        "text-anchor": nearRight ? "end" : "start",
      }, svg).textContent = m.label;
    }
  }
  if (spec.picked && Number.isFinite(spec.picked.x) && Number.isFinite(spec.picked.y)) {
    element("circle", { cx: px(spec.picked.x), cy: py(spec.picked.y), r: 7, class: "picked" }, plotArea);
  }
  if (spec.pickable && spec.onPick) {
    const hit = element("rect", { x: left, y: top, width: right - left, height: bottom - top, class: "hit" }, svg);
    hit.addEventListener("click", (event) => {
      const box = svg.getBoundingClientRect();
      const sx = ((event.clientX - box.left) / box.width) * width;
      const sy = ((event.clientY - box.top) / box.height) * height;
      let best = null;
      let bestDistance = Infinity;
      for (const [x, y, payload] of spec.pickable) {
        const distance = Math.hypot(px(x) - sx, py(y) - sy);
        if (distance < bestDistance) {
          bestDistance = distance;
          best = payload;
        }
      }
      if (best !== null && bestDistance < 40) spec.onPick(best);
    });
  }
}
