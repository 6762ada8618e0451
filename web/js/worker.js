// The Web Worker that runs the WebAssembly module (crates/web), so that the page never freezes
// while a diagram, an orbit or a map is computed. Messages: {id, method, request} with method
// one of the Explorer's (diagram, orbit, map, special_points, the exports); replies
// {id, ok: true, value, ms} or {id, ok: false, error, fatal, ms}. `fatal` marks a trap of the
// module (a bug, not an input error): the page then starts a new worker.
import init, { Explorer } from "../pkg/drumroll_web.js";

const METHODS = new Set([
  "catalogue", "diagram", "special_points", "diagram_json", "diagram_csv", "diagram_svg",
  "orbit", "orbit_json", "orbit_svg", "map", "map_json", "map_csv", "map_svg",
]);

const ready = init().then(() => new Explorer());

self.onmessage = async (event) => {
  const { id, method, request } = event.data;
  let explorer;
  try {
    explorer = await ready;
  } catch (error) {
    self.postMessage({ id, ok: false, fatal: true, error: `the WebAssembly module did not load: ${error}`, ms: 0 });
    return;
  }
  if (!METHODS.has(method)) {
    self.postMessage({ id, ok: false, fatal: false, error: `unknown method ${method}`, ms: 0 });
    return;
  }
  const start = performance.now();
  try {
    const value = request === undefined ? explorer[method]() : explorer[method](request);
    self.postMessage({ id, ok: true, value, ms: performance.now() - start });
  } catch (error) {
    // The module throws a string for a user's error; anything else is a trap.
    const fatal = typeof error !== "string";
    self.postMessage({ id, ok: false, fatal, error: fatal ? `internal error: ${error}` : error, ms: performance.now() - start });
  }
};
