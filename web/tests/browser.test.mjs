// Browser tests of the explorer page (web/dist, built by scripts/build-web.sh): Debian's
// headless Chromium driven by puppeteer-core, the page served from a loopback static server.
// Run by web/tests/run.sh, which installs Chromium and the node packages and sets DRUMROLL to
// the native CLI (the reference the page must agree with). Prints the timings it measures.
import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { createServer } from "node:http";
import { readFile, mkdtemp, mkdir, rm, writeFile, stat } from "node:fs/promises";
import { execFileSync } from "node:child_process";
import { tmpdir } from "node:os";
import path from "node:path";
import { fileURLToPath } from "node:url";
import puppeteer from "puppeteer-core";

const here = path.dirname(fileURLToPath(import.meta.url));
const dist = path.resolve(here, "../dist");
const artifacts = path.resolve(here, "artifacts");
const drumroll = process.env.DRUMROLL ?? "drumroll";
const chromium = process.env.CHROMIUM ?? "/usr/bin/chromium";
// Page events (a computation in the worker) get this long before a test gives up.
const WAIT_MS = 60_000;

const TYPES = {
  ".html": "text/html; charset=utf-8",
  ".js": "text/javascript; charset=utf-8",
  ".css": "text/css; charset=utf-8",
  ".wasm": "application/wasm",
  ".json": "application/json",
};

let server;
let origin;
let browser;
let userDataDir;
const timings = {};

before(async () => {
  await stat(path.join(dist, "index.html")).catch(() => {
    throw new Error(`${dist}/index.html is missing: run bash scripts/build-web.sh first`);
  });
  server = createServer(async (request, response) => {
    const url = new URL(request.url, "http://localhost");
    const file = path.join(dist, path.normalize(decodeURIComponent(url.pathname)).replace(/^(\.\.[/\\])+/, ""));
    const target = file.endsWith(path.sep) ? path.join(file, "index.html") : file;
    try {
      const body = await readFile(target);
      response.writeHead(200, { "content-type": TYPES[path.extname(target)] ?? "application/octet-stream" });
      response.end(body);
    } catch {
      response.writeHead(404);
      response.end("not found");
    }
  });
  await new Promise((resolve) => server.listen(0, "127.0.0.1", resolve));
  origin = `http://127.0.0.1:${server.address().port}`;
  userDataDir = await mkdtemp(path.join(tmpdir(), "drumroll-chromium-"));
  browser = await puppeteer.launch({
    executablePath: chromium,
    headless: true,
    userDataDir,
    args: [
      "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
      "--disable-background-networking", "--disable-component-update", "--disable-sync",
    ],
  });
  await mkdir(artifacts, { recursive: true });
});

after(async () => {
  await browser?.close();
  server?.close();
  if (userDataDir) await rm(userDataDir, { recursive: true, force: true });
  if (Object.keys(timings).length) {
    console.log("\nmeasured timings (ms):");
    for (const [name, value] of Object.entries(timings)) console.log(`  ${name}: ${typeof value === "number" ? value.toFixed(1) : value}`);
  }
});

/** A new page with its console errors collected. */
async function open(query = "") {
  const page = await browser.newPage();
  await page.setViewport({ width: 1500, height: 1300 });
  const errors = [];
  page.on("pageerror", (error) => errors.push(String(error)));
  page.on("console", (message) => {
    if (message.type() === "error") errors.push(message.text());
  });
  const started = Date.now();
  await page.goto(`${origin}/${query}`, { waitUntil: "load" });
  return { page, errors, started };
}

/** Wait until the page has drawn more than `count` diagrams. */
async function diagramsDrawn(page, count) {
  await page.waitForFunction((n) => window.drumroll && window.drumroll.diagramsDrawn > n, { timeout: WAIT_MS }, count);
}

/** The native CLI's `continue --json` object and its wall time, ms. */
function nativeContinue(args) {
  const start = process.hrtime.bigint();
  const text = execFileSync(drumroll, ["continue", ...args, "--json"], { encoding: "utf8" });
  const ms = Number(process.hrtime.bigint() - start) / 1e6;
  return { object: JSON.parse(text), ms };
}

test("the page loads and draws the default diagram", async () => {
  const { page, errors, started } = await open();
  await diagramsDrawn(page, 0);
  timings["first diagram on screen, since navigation start (performance.now)"] = await page.evaluate(() => window.drumroll.firstDiagramMs);
  timings["first diagram on screen, wall time from goto"] = Date.now() - started;
  assert.equal(await page.$eval("#error", (e) => e.hidden), true);
  const curves = await page.$$eval("#plot-phase-ratio path.curve", (paths) => paths.length);
  assert.ok(curves > 0, "the Fig. 2 panel has curves");
  const labels = await page.$$eval("#special-points tbody tr td:first-child", (cells) => cells.map((c) => c.textContent));
  assert.ok(labels.includes("G1") && labels.includes("G2"), `special points: ${labels}`);
  assert.deepEqual(errors, []);
  await page.close();
});

test("the report hook gives the CLI's special points of biolever-mica to 1e-9 nm", async () => {
  const { page, errors } = await open("?case=biolever-mica&report=1");
  await page.waitForFunction(() => document.getElementById("report").textContent.length > 0, { timeout: WAIT_MS });
  const report = JSON.parse(await page.$eval("#report", (e) => e.textContent));
  timings["biolever-mica diagram, browser (wasm in the worker)"] = await page.evaluate(() => window.drumroll.lastComputeMs);
  const native = nativeContinue(["--case", "biolever-mica"]);
  timings["biolever-mica diagram, native CLI (process wall time)"] = native.ms;
  const expected = native.object.special_points;
  assert.ok(Array.isArray(report), JSON.stringify(report).slice(0, 300));
  assert.deepEqual(report.map((s) => s.label), expected.map((s) => s.label));
  report.forEach((point, i) => {
    const cli = expected[i];
    assert.deepEqual(Object.keys(point).sort(), Object.keys(cli).sort(), "the CLI's keys");
    for (const key of ["z_nm", "amplitude_ratio", "phase_deg", "precision_nm"]) {
      assert.ok(Math.abs(point[key] - cli[key]) <= 1e-9, `${cli.label} ${key}: ${point[key]} vs ${cli[key]}`);
    }
    point.bracket_nm.forEach((z, j) => assert.ok(Math.abs(z - cli.bracket_nm[j]) <= 1e-9, `${cli.label} bracket`));
    point.state.forEach((x, j) => assert.ok(Math.abs(x - cli.state[j]) <= 1e-9, `${cli.label} state[${j}]`));
    for (const key of ["impacts_before", "impacts_after", "converged"]) assert.equal(point[key], cli[key], `${cli.label} ${key}`);
  });
  assert.deepEqual(errors, []);
  await page.close();
});

test("a slider move recomputes, a click shows the orbit, and the screenshot shows the plot", async () => {
  const { page, errors } = await open("?case=biolever-mica");
  await diagramsDrawn(page, 0);
  const g1Before = await page.$eval("#special-points tbody tr td:nth-child(2)", (c) => c.textContent);
  const roundTrips = [];
  const computes = [];
  const natives = [];
  let nativeLast;
  for (const a0 of [12, 8, 15]) {
    const drawn = await page.evaluate(() => window.drumroll.diagramsDrawn);
    const start = Date.now();
    await page.$eval("#a0-slider", (slider, value) => {
      slider.value = String(value);
      slider.dispatchEvent(new Event("input", { bubbles: true }));
    }, a0);
    await diagramsDrawn(page, drawn);
    roundTrips.push(Date.now() - start);
    computes.push(await page.evaluate(() => window.drumroll.lastComputeMs));
    nativeLast = nativeContinue(["--case", "biolever-mica", "--a0", String(a0)]);
    natives.push(nativeLast.ms);
    assert.equal(await page.$eval("#a0", (input) => input.value), String(a0));
  }
  timings["slider move to redrawn diagram, browser wall times (A0 = 12, 8, 15 nm)"] = roundTrips.join(", ");
  timings["recomputation in the worker, browser (A0 = 12, 8, 15 nm)"] = computes.map((m) => m.toFixed(0)).join(", ");
  timings["same diagrams, native CLI process wall times"] = natives.map((m) => m.toFixed(0)).join(", ");
  const g1After = await page.$eval("#special-points tbody tr td:nth-child(2)", (c) => c.textContent);
  assert.notEqual(g1After, g1Before, "G1 moves with A0");
  const g1Native = nativeLast.object.special_points.find((p) => p.label === "G1").z_nm;
  // The table prints 10 decimals.
  assert.ok(Math.abs(Number(g1After) - g1Native) < 1e-9, `G1 at A0 = 15 nm: ${g1After} vs the CLI's ${g1Native}`);

  // A click in the middle of the A/A0-vs-Z panel's curve: the orbit and its observables.
  const box = await (await page.$("#plot-ratio-z")).boundingBox();
  const target = await page.evaluate(() => {
    const path = document.querySelector("#plot-ratio-z path.curve");
    const point = path.getPointAtLength(path.getTotalLength() / 2);
    const svg = path.ownerSVGElement;
    const view = svg.viewBox.baseVal;
    const rect = svg.getBoundingClientRect();
    return { x: (point.x / view.width) * rect.width, y: (point.y / view.height) * rect.height };
  });
  await page.mouse.click(box.x + target.x, box.y + target.y);
  await page.waitForFunction(() => window.drumroll.orbitsDrawn > 0, { timeout: WAIT_MS });
  const rows = await page.$$eval("#observables tbody tr", (r) => r.length);
  assert.ok(rows >= 13, `observables rows: ${rows}`);
  assert.ok(await page.$eval("#plot-force path.curve", (p) => p.getAttribute("d").length > 100));

  const shot = path.join(artifacts, "page.png");
  await page.screenshot({ path: shot, fullPage: true });
  // The Fig. 2 panel's own pixels: the approach branch's blue must be drawn there.
  const plot = await page.$("#plot-phase-ratio");
  const image = await plot.screenshot({ encoding: "base64" });
  await writeFile(path.join(artifacts, "fig2-panel.png"), Buffer.from(image, "base64"));
  const blue = await page.evaluate(async (data) => {
    const img = new Image();
    img.src = `data:image/png;base64,${data}`;
    await img.decode();
    const canvas = new OffscreenCanvas(img.width, img.height);
    const context = canvas.getContext("2d");
    context.drawImage(img, 0, 0);
    const pixels = context.getImageData(0, 0, img.width, img.height).data;
    let count = 0;
    for (let i = 0; i < pixels.length; i += 4) {
      // #1f5fbf = (31, 95, 191), anti-aliased edges aside.
      if (Math.abs(pixels[i] - 31) < 40 && Math.abs(pixels[i + 1] - 95) < 40 && pixels[i + 2] > 150) count++;
    }
    return { count, width: img.width };
  }, image);
  // The branch spans the panel's width (less its 76 px of margins) in a line 1.6 px wide: at
  // least half a pixel of blue per column, and none before the diagram is drawn.
  assert.ok(blue.count > 0.5 * (blue.width - 76), `blue curve pixels in the screenshot of the Fig. 2 panel: ${blue.count} (panel ${blue.width} px wide)`);
  assert.ok((await stat(shot)).size > 30_000, "the page screenshot has content");
  assert.deepEqual(errors, []);
  await page.close();
});

test("errors in the inputs show a message on the page, not a stack trace", async () => {
  const { page, errors } = await open("?case=biolever-mica");
  await diagramsDrawn(page, 0);
  const set = (selector, value) => page.$eval(selector, (input, v) => {
    input.value = v;
    input.dispatchEvent(new Event("change", { bubbles: true }));
  }, value);
  // Out of range: the module's message, as the command line's.
  await set("#a0", "-5");
  await page.waitForFunction(() => !document.getElementById("error").hidden, { timeout: WAIT_MS });
  let message = await page.$eval("#error", (e) => e.textContent);
  assert.match(message, /--a0 -5: .*allowed/);
  // Not a number: the field named, nothing sent.
  await set("#a0", "10");
  await page.waitForFunction(() => document.getElementById("error").hidden, { timeout: WAIT_MS });
  await set("#cantilever-tip_radius_nm", "");
  message = await page.$eval("#error", (e) => e.textContent);
  assert.match(message, /tip radius R \(nm\): "" is not a number/);
  // A contact law's parameter out of range: the field and its range.
  await set("#cantilever-tip_radius_nm", "30");
  await page.select("#contact-law", "dmt");
  await set("#contact-hamaker_constant_j", "1");
  await page.waitForFunction(() => /hamaker_constant_j/.test(document.getElementById("error").textContent), { timeout: WAIT_MS });
  message = await page.$eval("#error", (e) => e.textContent);
  assert.match(message, /the page's sample.*hamaker_constant_j.*1e-18/s);
  for (const text of [message]) assert.doesNotMatch(text, /RuntimeError|unreachable|\.wasm|at \w+ \(/);
  // An unknown case in the report hook: a message, and the report says so.
  const other = await open("?case=no-such-case&report=1");
  await other.page.waitForFunction(() => document.getElementById("report").textContent.length > 0, { timeout: WAIT_MS });
  const report = JSON.parse(await other.page.$eval("#report", (e) => e.textContent));
  assert.match(report.error, /no-such-case/);
  assert.deepEqual(errors, []);
  await other.page.close();
  await page.close();
});

test("the exports are the CLI's: CSV to 1e-9, the SVG figure", async () => {
  const { page, errors } = await open("?case=biolever-mica");
  await diagramsDrawn(page, 0);
  const csv = await page.evaluate(() => window.drumroll.exportText("diagram_csv"));
  const svg = await page.evaluate(() => window.drumroll.exportText("diagram_svg"));
  const json = JSON.parse(await page.evaluate(() => window.drumroll.exportText("diagram_json")));
  const scratch = await mkdtemp(path.join(tmpdir(), "drumroll-web-export-"));
  try {
    const files = { csv: path.join(scratch, "d.csv"), svg: path.join(scratch, "d.svg") };
    execFileSync(drumroll, ["continue", "--case", "biolever-mica", "--quiet", "--csv", files.csv, "--plot", files.svg]);
    const cliCsv = (await readFile(files.csv, "utf8")).trim().split("\n");
    const pageCsv = csv.trim().split("\n");
    assert.equal(pageCsv[0], cliCsv[0], "the CSV header");
    assert.equal(pageCsv.length, cliCsv.length, "the CSV rows");
    // The module and the CLI run the same code, but wasm32's sin, cos, exp (Rust's libm port)
    // and the native glibc's differ in the last bit: every converged number agrees to 1e-9,
    // while Newton's statistics (iterations, residual, both at roundoff) may differ.
    const header = cliCsv[0].split(",");
    const statistics = new Set(["iterations", "residual"].map((name) => header.indexOf(name)));
    // A harmonic's phase is compared where its amplitude is resolved: on the free orbit near
    // first contact the harmonics n >= 2 vanish (closed form: exactly 0) and their computed
    // amplitudes are roundoff, whose phase is any angle. Elsewhere the phase's tolerance is the
    // components' 1e-9 (relative to the orbit's scale, the first harmonic's amplitude) carried
    // to the angle: 1e-9 max(1, |U_1|) / |U_n| rad.
    const phaseOf = new Map(
      header
        .map((name, j) => [name.match(/^harmonic_(\d+)_phase_deg$/), j])
        .filter(([match]) => match)
        .map(([match, j]) => [j, header.indexOf(`harmonic_${match[1]}_amplitude_nm`)]),
    );
    pageCsv.forEach((line, i) => {
      const ours = line.split(",");
      const theirs = cliCsv[i].split(",");
      ours.forEach((cell, j) => {
        if (statistics.has(j)) return;
        let tolerance = 1e-9 * Math.max(1, Math.abs(Number(theirs[j])));
        if (phaseOf.has(j)) {
          const amplitude = Math.abs(Number(theirs[phaseOf.get(j)]));
          if (amplitude < 1e-6) return;
          const scale = Math.max(1, Math.abs(Number(theirs[header.indexOf("harmonic_1_amplitude_nm")])));
          tolerance = Math.max(tolerance, (1e-9 * scale / amplitude) * (180 / Math.PI));
        }
        const a = Number(cell);
        const b = Number(theirs[j]);
        if (Number.isFinite(a) && Number.isFinite(b) && cell !== "" && theirs[j] !== "") {
          assert.ok(Math.abs(a - b) <= tolerance, `row ${i} column ${j}: ${cell} vs ${theirs[j]}`);
        } else {
          assert.equal(cell, theirs[j], `row ${i} column ${j}`);
        }
      });
    });
    const cliSvg = await readFile(files.svg, "utf8");
    await writeFile(path.join(artifacts, "diagram-page.svg"), svg);
    await writeFile(path.join(artifacts, "diagram-cli.svg"), cliSvg);
    // The figure: identical but for the curves' polylines, which the decimation to pixel
    // columns may thin by a point where a last-bit difference moves a point across a pixel's
    // rounding (as measured: one point of 260 on one curve); axes, ticks, labels, markers agree.
    const polylines = /points="([^"]*)"/g;
    assert.equal(svg.replace(polylines, 'points=""'), cliSvg.replace(polylines, 'points=""'), "the SVG figure without its polylines");
    const counts = (text) => [...text.matchAll(polylines)].map((m) => m[1].split(" ").length);
    const ours = counts(svg);
    const theirs = counts(cliSvg);
    assert.equal(ours.length, theirs.length, "the number of polylines");
    ours.forEach((n, i) => assert.ok(Math.abs(n - theirs[i]) <= Math.max(1, 0.01 * theirs[i]), `polyline ${i}: ${n} vs ${theirs[i]} points`));
    assert.equal(json.case, "biolever-mica");
    assert.equal(json.points.length, pageCsv.length - 1);
  } finally {
    await rm(scratch, { recursive: true, force: true });
  }
  assert.deepEqual(errors, []);
  await page.close();
});

test("the regime-map tab draws the curves of drumroll map", async () => {
  const { page, errors } = await open("?case=biolever-mica");
  await diagramsDrawn(page, 0);
  await page.click("#tab-map");
  assert.equal(await page.$eval("#panel-map", (e) => e.hidden), false);
  await page.$eval("#map-from", (e) => { e.value = "5"; });
  await page.$eval("#map-to", (e) => { e.value = "20"; });
  await page.$eval("#map-points", (e) => { e.value = "40"; });
  const start = Date.now();
  await page.click("#map-form button[type=submit]");
  await page.waitForFunction(() => window.drumroll.mapsDrawn > 0 || !document.getElementById("error").hidden, { timeout: WAIT_MS });
  assert.equal(await page.$eval("#error", (e) => e.hidden), true, await page.$eval("#error", (e) => e.textContent));
  timings["regime map over a0 in [5, 20] nm, 40 points, browser wall time"] = Date.now() - start;
  const map = JSON.parse(await page.evaluate(() => window.drumroll.exportText("map_json")));
  const startNative = process.hrtime.bigint();
  const native = JSON.parse(execFileSync(drumroll, ["map", "--case", "biolever-mica", "--vary", "a0", "--from", "5", "--to", "20", "--points", "40", "--json"], { encoding: "utf8" }));
  timings["same map, native CLI process wall time"] = Number(process.hrtime.bigint() - startNative) / 1e6;
  assert.deepEqual(map.curves.map((c) => c.label), native.curves.map((c) => c.label));
  // Curve points are Newton solutions to a residual of 1e-10 nm, whose Z the last-bit
  // differences of wasm32's and glibc's sin, cos and exp move by up to the residual over the
  // gap's sensitivity: 1e-8 nm bounds it; the curves' shapes and counts agree exactly.
  let largest = 0;
  map.curves.forEach((curve, i) => {
    const cli = native.curves[i];
    // Points between are wherever the arclength steps fall (on the same curve); the points at
    // fixed values of the parameter (the range's ends, the case's own) are compared.
    const fixed = (points) => points.filter((p) => p.at_fixed_parameter);
    const ours = fixed(curve.points);
    const theirs = fixed(cli.points);
    assert.deepEqual(ours.map((p) => p.parameter), theirs.map((p) => p.parameter), `${curve.label}: the fixed values`);
    assert.ok(ours.length >= 2, `${curve.label}: at least the range's ends`);
    ours.forEach((p, j) => {
      const difference = Math.abs(p.z_nm - theirs[j].z_nm);
      largest = Math.max(largest, difference);
      assert.ok(difference <= 1e-8, `${curve.label} at ${p.parameter}: Z ${p.z_nm} vs ${theirs[j].z_nm}`);
    });
  });
  timings["map curve points, largest |difference| from the CLI's (nm)"] = largest.toExponential(2);
  const curves = await page.$$eval("#plot-map-z path.curve", (paths) => paths.length);
  assert.ok(curves >= map.curves.length, `curves drawn: ${curves}`);
  await page.screenshot({ path: path.join(artifacts, "map.png") });
  assert.deepEqual(errors, []);
  await page.close();
});
