// The page's side of the worker (worker.js): calls as promises, a new worker after a trap, and
// "latest wins" for requests that a newer one makes obsolete (a slider dragged: only the last
// position's diagram is computed once the running one ends, or at once when the running one
// has taken over a second: its worker is then replaced).

/** A running call made obsolete is abandoned (the worker restarted) after this long, ms. */
const RESTART_AFTER_MS = 1000;

export class Compute {
  constructor() {
    this.nextId = 1;
    this.waiting = new Map();
    this.pending = new Map(); // kind -> {method, request, resolve, reject}
    this.busy = new Map(); // kind -> true while a call of that kind runs
    this.start();
  }

  start() {
    this.worker = new Worker(new URL("./worker.js", import.meta.url), { type: "module" });
    this.worker.onmessage = (event) => {
      const reply = event.data;
      const call = this.waiting.get(reply.id);
      if (!call) return;
      this.waiting.delete(reply.id);
      if (reply.fatal) {
        // A trap leaves the module's memory in doubt: start afresh (the last results are lost).
        this.worker.terminate();
        for (const other of this.waiting.values()) other.reject(new Error("the module was restarted"));
        this.waiting.clear();
        this.start();
      }
      if (reply.ok) call.resolve({ value: reply.value, ms: reply.ms });
      else call.reject(Object.assign(new Error(reply.error), { fatal: reply.fatal }));
    };
    this.worker.onerror = (event) => {
      for (const call of this.waiting.values()) call.reject(new Error(`the worker failed: ${event.message}`));
      this.waiting.clear();
    };
  }

  /** Call `method` of the module's Explorer with the text `request` (`kind` tags the call). */
  call(method, request, kind = "other") {
    const id = this.nextId++;
    return new Promise((resolve, reject) => {
      this.waiting.set(id, { resolve, reject, kind, since: performance.now() });
      this.worker.postMessage({ id, method, request });
    });
  }

  /**
   * Stop the worker when it only runs an obsolete call of `kind` that has run for over
   * `RESTART_AFTER_MS` (a long diagram while the slider moves on): that call resolves to null
   * (superseded) and a new worker starts, so the newest request need not wait for it.
   */
  abandon(kind) {
    const calls = [...this.waiting.values()];
    const now = performance.now();
    if (calls.length === 0 || calls.some((c) => c.kind !== kind || now - c.since < RESTART_AFTER_MS)) return;
    this.worker.terminate();
    for (const call of calls) call.resolve(null);
    this.waiting.clear();
    this.start();
  }

  /**
   * Call `method` for `kind` ("diagram", "orbit", "map"): while one of that kind runs, a newer
   * call replaces the waiting one (whose promise resolves to null: superseded).
   */
  latest(kind, method, request) {
    return new Promise((resolve, reject) => {
      const previous = this.pending.get(kind);
      if (previous) previous.resolve(null);
      this.pending.set(kind, { method, request, resolve, reject });
      if (this.busy.get(kind)) this.abandon(kind);
      this.drain(kind);
    });
  }

  drain(kind) {
    if (this.busy.get(kind)) return;
    const next = this.pending.get(kind);
    if (!next) return;
    this.pending.delete(kind);
    this.busy.set(kind, true);
    this.call(next.method, next.request, kind)
      .then(next.resolve, next.reject)
      .finally(() => {
        this.busy.set(kind, false);
        this.drain(kind);
      });
  }
}
