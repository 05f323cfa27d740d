// arbor view's page. It holds no rendering logic: it moves the camera (orbit, pan, zoom), asks the
// server for views, draws the images, overlays and ray segments the server returns, and charts the
// server's figures. The API is described in docs/view.md.
"use strict";

const token = new URLSearchParams(location.search).get("token") || "";
const $ = (id) => document.getElementById(id);

/** A request to the API with the token; JSON bodies go as JSON. */
async function api(path, options = {}) {
  const headers = { "X-Arbor-Token": token };
  if (options.body !== undefined) headers["Content-Type"] = "application/json";
  const r = await fetch(path, { ...options, headers });
  if (r.status >= 400) {
    let msg = r.statusText;
    try { msg = (await r.json()).error || msg; } catch (_) { /* not JSON */ }
    throw new Error(`${r.status}: ${msg}`);
  }
  return r;
}

// ---- vectors, for moving the camera ----
const add = (a, b) => a.map((v, i) => v + b[i]);
const sub = (a, b) => a.map((v, i) => v - b[i]);
const mul = (a, s) => a.map((v) => v * s);
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const len = (a) => Math.sqrt(dot(a, a));
const norm = (a) => mul(a, 1 / (len(a) || 1));
/** `v` turned by `angle` about the unit `axis` (Rodrigues). */
function rotate(v, axis, angle) {
  const c = Math.cos(angle), s = Math.sin(angle);
  return add(add(mul(v, c), mul(cross(axis, v), s)), mul(axis, dot(axis, v) * (1 - c)));
}

const state = {
  scene: null,
  camera: 0,
  eye: [0, 0, 0], gaze: [0, 0, -1], up: [0, 1, 0], target: [0, 0, -1], worldUp: [0, 1, 0],
  width: 480, height: 360,
  view: 0,          // the last view the server gave a number to
  seq: { render: 0, overlay: 0 },
  sending: false, dirty: false,
  lastFrame: null,  // figures of the last image drawn
};

/** The image size for the current camera: `width` wide, the camera's aspect. */
function viewSize() {
  const cam = state.scene.cameras[state.camera];
  const w = Math.max(16, Math.min(4096, Number($("width").value) || 480));
  const h = Math.max(1, Math.min(4096, Math.round(w * cam.height / cam.width)));
  return [w, h];
}

/** Back to camera `i` of the scene, its pose and the centre of the scene's bounds as orbit target. */
function resetCamera(i) {
  const cam = state.scene.cameras[i];
  state.camera = i;
  state.eye = cam.eye; state.gaze = norm(cam.gaze); state.up = cam.up; state.worldUp = cam.up;
  const b = state.scene.bounds;
  const centre = mul(add(b.min, b.max), 0.5);
  const along = dot(sub(centre, state.eye), state.gaze);
  state.target = add(state.eye, mul(state.gaze, along > 1e-6 ? along : len(sub(b.max, b.min)) || 1));
  $("integrator").value = cam.renderer;
  [state.width, state.height] = viewSize();
  sizeView();
  requestView();
}

function sizeView() {
  for (const id of ["render", "overlay"]) { $(id).width = state.width; $(id).height = state.height; }
  $("view").style.width = state.width + "px";
  $("view").style.height = state.height + "px";
  $("rays").setAttribute("viewBox", `0 0 ${state.width} ${state.height}`);
}

function overlayValue() {
  const kind = $("overlay-kind").value;
  return kind === "boxes" ? `boxes:${$("depth").value}` : kind;
}

/** Sends the current view; while one is on its way, the latest change waits and goes next. */
async function requestView() {
  if (state.sending) { state.dirty = true; return; }
  state.sending = true;
  delete $("view").dataset.asked;
  try {
    const body = {
      camera: state.camera, eye: state.eye, gaze: state.gaze, up: state.up,
      width: state.width, height: state.height, integrator: $("integrator").value,
      overlay: overlayValue(), spp: Math.max(1, Number($("spp").value) || 1),
    };
    const r = await api("/api/view", { method: "POST", body: JSON.stringify(body) });
    state.view = (await r.json()).view;
  } catch (e) {
    status(`view refused: ${e.message}`);
  }
  state.sending = false;
  if (state.dirty) { state.dirty = false; requestView(); return; }
  // The view the server is on, once no other is on its way; absent while one is (for the browser
  // test, with data-view: the page shows what it last asked for when both are equal).
  $("view").dataset.asked = String(state.view);
}

function status(text) { $("status").textContent = text; }

/** Draws RGB bytes of `w` x `h` on `canvas` (scaled up when the image is a low-resolution preview). */
function drawRgb(canvas, bytes, w, h) {
  const rgba = new Uint8ClampedArray(w * h * 4);
  for (let i = 0, j = 0; i < w * h; i++, j += 3) {
    rgba[4 * i] = bytes[j]; rgba[4 * i + 1] = bytes[j + 1]; rgba[4 * i + 2] = bytes[j + 2]; rgba[4 * i + 3] = 255;
  }
  const image = new ImageData(rgba, w, h);
  const ctx = canvas.getContext("2d");
  if (w === canvas.width && h === canvas.height) { ctx.putImageData(image, 0, 0); return; }
  const small = document.createElement("canvas");
  small.width = w; small.height = h;
  small.getContext("2d").putImageData(image, 0, 0);
  ctx.imageSmoothingEnabled = false;
  ctx.drawImage(small, 0, 0, canvas.width, canvas.height);
}

/** Fetches the images of one channel as they come, forever. */
async function follow(channel) {
  for (;;) {
    try {
      const r = await api(`/api/image?channel=${channel}&after=${state.seq[channel]}&wait=20000`);
      if (r.status === 204) continue;
      const h = (k) => r.headers.get(k);
      const bytes = new Uint8Array(await r.arrayBuffer());
      state.seq[channel] = Number(h("x-seq"));
      // Images of an older view are skipped: the camera has moved on.
      if (Number(h("x-view")) < state.view) continue;
      const w = Number(h("x-width")), ht = Number(h("x-height"));
      drawRgb($(channel), bytes, w, ht);
      if (channel === "render") {
        state.lastFrame = { samples: Number(h("x-samples")), ms: Number(h("x-render-ms")), mrays: Number(h("x-mrays")),
          convert: Number(h("x-convert-ms")), w, h: ht, seq: state.seq.render };
        const f = state.lastFrame;
        status(`${f.samples ? f.samples + " spp" : "preview"} · ${w}x${ht} · frame ${f.ms.toFixed(1)} ms · ` +
          `${f.mrays.toFixed(2)} Mrays/s · server ${f.convert.toFixed(1)} ms · view ${state.view}`);
        $("view").dataset.samples = String(f.samples);
        $("view").dataset.seq = String(f.seq);
        $("view").dataset.view = h("x-view");
      } else {
        const max = h("x-heatmap-max");
        $("heatmap-legend").hidden = max === null;
        if (max !== null) $("heatmap-max").textContent = max;
        $("view").dataset.overlaySeq = String(state.seq.overlay);
      }
    } catch (e) {
      status(`lost the server: ${e.message}`);
      await new Promise((ok) => setTimeout(ok, 1000));
    }
  }
}

function applyOverlay() {
  const none = $("overlay-kind").value === "none";
  $("overlay").style.display = none ? "none" : "block";
  $("overlay").style.opacity = String(Number($("opacity").value) / 100);
  $("depth-value").textContent = $("depth").value;
  if (none) $("heatmap-legend").hidden = true;
}

// ---- moving the camera ----
function orbit(dx, dy) {
  let offset = sub(state.eye, state.target);
  offset = rotate(offset, norm(state.worldUp), -dx * 0.01);
  const right = norm(cross(offset, state.worldUp));
  const turned = rotate(offset, right, dy * 0.01);
  // Stop short of the poles, where the up vector would flip.
  if (Math.abs(dot(norm(turned), norm(state.worldUp))) < 0.995) offset = turned;
  state.eye = add(state.target, offset);
  state.gaze = norm(sub(state.target, state.eye));
  state.up = state.worldUp;
  requestView();
}
function pan(dx, dy) {
  const distance = len(sub(state.target, state.eye));
  const right = norm(cross(state.gaze, state.up));
  const up = norm(cross(right, state.gaze));
  const move = add(mul(right, -dx * distance * 0.002), mul(up, dy * distance * 0.002));
  state.eye = add(state.eye, move); state.target = add(state.target, move);
  requestView();
}
function zoom(factor) {
  state.eye = add(state.target, mul(sub(state.eye, state.target), factor));
  requestView();
}

function setupMouse() {
  const view = $("view");
  let drag = null;
  view.addEventListener("contextmenu", (e) => e.preventDefault());
  view.addEventListener("pointerdown", (e) => {
    drag = { x: e.clientX, y: e.clientY, x0: e.clientX, y0: e.clientY, pan: e.button === 2 || e.shiftKey, moved: false };
    view.setPointerCapture(e.pointerId);
  });
  view.addEventListener("pointermove", (e) => {
    if (!drag) return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    if (Math.abs(e.clientX - drag.x0) + Math.abs(e.clientY - drag.y0) > 3) drag.moved = true;
    if (!drag.moved || (dx === 0 && dy === 0)) return;
    drag.x = e.clientX; drag.y = e.clientY;
    if (drag.pan) pan(dx, dy); else orbit(dx, dy);
  });
  view.addEventListener("pointerup", (e) => {
    if (drag && !drag.moved) {
      const r = view.getBoundingClientRect();
      const x = Math.floor((e.clientX - r.left) * state.width / r.width);
      const y = Math.floor((e.clientY - r.top) * state.height / r.height);
      inspect(x, y);
    }
    drag = null;
  });
  view.addEventListener("wheel", (e) => { e.preventDefault(); zoom(e.deltaY > 0 ? 1.1 : 1 / 1.1); }, { passive: false });
  view.addEventListener("keydown", (e) => {
    const keys = { ArrowLeft: () => orbit(-15, 0), ArrowRight: () => orbit(15, 0), ArrowUp: () => orbit(0, -15),
      ArrowDown: () => orbit(0, 15), "+": () => zoom(1 / 1.1), "=": () => zoom(1 / 1.1), "-": () => zoom(1.1),
      r: () => resetCamera(state.camera), R: () => resetCamera(state.camera) };
    if (keys[e.key]) { e.preventDefault(); keys[e.key](); }
  });
}

// ---- the ray inspector ----
const fmt = (v) => (v === null || v === undefined ? "–" : Array.isArray(v) ? v.map((x) => fmt(x)).join(", ") :
  typeof v === "number" ? (Number.isInteger(v) ? String(v) : v.toPrecision(4)) : String(v));

async function inspect(x, y) {
  $("inspect-summary").textContent = `pixel (${x}, ${y})…`;
  try {
    const r = await (await api(`/api/inspect?x=${x}&y=${y}`)).json();
    const body = $("inspector").tBodies[0];
    body.replaceChildren();
    const svg = $("rays");
    svg.replaceChildren();
    for (const ray of r.rays) {
      const tr = body.insertRow();
      tr.className = `kind-${ray.kind}`;
      const hit = ray.hit;
      const counts = ray.counts.map((c) => `${c.structure}: ${c.nodes}/${c.prims}`).join("; ");
      const cells = [ray.index, ray.kind, ray.parent, fmt(ray.origin), fmt(ray.direction),
        hit ? fmt(hit.t) : ray.occluded === null ? "miss" : ray.occluded ? "blocked" : "clear",
        hit ? `${hit.object} ${hit.object_name || ""}` : "", hit ? fmt(hit.triangle) : "",
        hit ? `${hit.material} (${hit.material_id})` : "", hit ? fmt([hit.u, hit.v]) : "", counts];
      for (const c of cells) tr.insertCell().textContent = c === null || c === undefined ? "–" : String(c);
      if (ray.segment) {
        const line = document.createElementNS("http://www.w3.org/2000/svg", "line");
        const [x1, y1, x2, y2] = ray.segment;
        Object.entries({ x1, y1, x2, y2 }).forEach(([k, v]) => line.setAttribute(k, v));
        line.setAttribute("class", `kind-${ray.kind}`);
        line.setAttribute("stroke", getComputedStyle(tr).color);
        svg.appendChild(line);
      }
    }
    const first = r.rays[0] && r.rays[0].hit;
    $("inspect-summary").textContent = `pixel (${x}, ${y}): ${r.rays.length} rays, radiance ${fmt(r.radiance)}` +
      (first ? `, camera ray hits object ${first.object} triangle ${fmt(first.triangle)}` : ", camera ray misses");
    $("inspect-panel").dataset.prim = first ? String(first.prim_id) : "";
    $("inspect-panel").dataset.primColor = first ? first.prim_color.join(",") : "";
    $("inspect-panel").dataset.triangle = first && first.triangle !== null ? String(first.triangle) : "";
    $("inspect-panel").dataset.pixel = `${x},${y}`;
  } catch (e) {
    $("inspect-summary").textContent = `pixel (${x}, ${y}): ${e.message}`;
  }
}

// ---- the structure ----
function showStats(s, building) {
  const rows = [["structure", s.kind], ["build", `${s.build_ms.toFixed(1)} ms`], ["nodes", s.nodes], ["leaves", s.leaves],
    ["depth", `max ${s.max_depth}, mean ${s.mean_depth.toFixed(1)}`], ["memory", `${s.bytes} B (${s.bytes_per_triangle.toFixed(1)} B/triangle)`],
    ["SAH cost", s.sah_cost.toFixed(2)], ["primitives per leaf", s.mean_leaf_prims.toFixed(2)],
    ["references per primitive", s.refs_per_prim.toFixed(2)], ["triangles", s.triangles], ["spheres", s.spheres]];
  const body = $("stats").tBodies[0];
  body.replaceChildren();
  for (const [k, v] of rows) { const tr = body.insertRow(); tr.insertCell().textContent = k; tr.insertCell().textContent = v; }
  $("stats").dataset.kind = s.kind;
  $("depth").max = String(s.max_depth);
  if (!building) $("build-status").textContent = "";
}

function showParams(kind, values = {}) {
  const spec = state.scene.kinds.find((k) => k.kind === kind);
  const box = $("params");
  box.replaceChildren();
  for (const p of spec.params) {
    const label = document.createElement("label");
    label.title = `${p.about} (${p.range})`;
    const input = document.createElement("input");
    input.id = `param-${p.key}`;
    input.value = values[p.key] !== undefined ? values[p.key] : p.default;
    label.append(`${p.key} `, input);
    box.appendChild(label);
  }
}

async function rebuild() {
  const kind = $("kind").value;
  const spec = state.scene.kinds.find((k) => k.kind === kind);
  const params = {};
  for (const p of spec.params) params[p.key] = $(`param-${p.key}`).value;
  // Said before the request: a small structure's "done" event can arrive before the request returns,
  // and must not be overwritten by "building" afterwards.
  $("build-status").textContent = `building ${kind}…`;
  try {
    await api("/api/accel", { method: "POST", body: JSON.stringify({ kind, params }) });
  } catch (e) {
    $("build-status").textContent = e.message;
  }
}

// ---- side by side ----
async function compare() {
  const [a, b] = [$("compare-a").value, $("compare-b").value];
  $("compare-scale").textContent = `building and rendering ${a} and ${b}…`;
  try {
    const r = await (await api(`/api/compare?a=${a}&b=${b}`)).json();
    for (const [i, s] of r.structures.entries()) {
      const which = i === 0 ? "a" : "b";
      const img = await api(`/api/compare/image?kind=${s.kind}`);
      const bytes = new Uint8Array(await img.arrayBuffer());
      const canvas = $(`heat-${which}`);
      canvas.width = Number(img.headers.get("x-width")); canvas.height = Number(img.headers.get("x-height"));
      drawRgb(canvas, bytes, canvas.width, canvas.height);
      $(`heat-${which}-caption`).textContent = `${s.kind}: max ${s.max}, ${s.stats.nodes} nodes, build ${s.stats.build_ms.toFixed(1)} ms`;
    }
    $("compare-scale").textContent = `one colour scale: 0 to ${r.scale} nodes visited + primitives tested per pixel`;
    $("compare-scale").dataset.scale = String(r.scale);
  } catch (e) {
    $("compare-scale").textContent = e.message;
  }
}

// ---- the benchmark chart: one bar chart per figure, a bar per structure ----
function chart(rows) {
  const figures = [["build ms", (r) => r.stats.build_ms], ["Mrays/s primary", (r) => r.mrays_primary],
    ["Mrays/s diffuse", (r) => r.mrays_diffuse], ["bytes per triangle", (r) => r.stats.bytes_per_triangle]];
  const box = $("bench-chart");
  box.replaceChildren();
  const ns = "http://www.w3.org/2000/svg";
  for (const [title, value] of figures) {
    const w = 300, bar = 16, h = 22 + rows.length * (bar + 4);
    const svg = document.createElementNS(ns, "svg");
    svg.setAttribute("width", w); svg.setAttribute("height", h);
    const text = (x, y, s, anchor = "start") => {
      const t = document.createElementNS(ns, "text");
      t.setAttribute("x", x); t.setAttribute("y", y); t.setAttribute("text-anchor", anchor); t.textContent = s;
      svg.appendChild(t);
    };
    text(0, 14, title);
    const max = Math.max(...rows.map(value), 1e-9);
    rows.forEach((r, i) => {
      const y = 22 + i * (bar + 4), v = value(r), bw = (w - 170) * v / max;
      text(96, y + 12, r.kind, "end");
      const rect = document.createElementNS(ns, "rect");
      Object.entries({ x: 100, y, width: Math.max(bw, 1), height: bar, fill: "#5b9bd5" }).forEach(([k, val]) => rect.setAttribute(k, val));
      svg.appendChild(rect);
      text(104 + bw, y + 12, v >= 100 ? v.toFixed(0) : v.toFixed(2));
    });
    box.appendChild(svg);
  }
  box.dataset.rows = String(rows.length);
}

async function bench() {
  try {
    await api("/api/bench", { method: "POST" });
    $("bench-status").textContent = "measuring…";
  } catch (e) {
    $("bench-status").textContent = e.message;
  }
}

// ---- events from the server ----
function listen() {
  const events = new EventSource(`/api/events?token=${encodeURIComponent(token)}`);
  events.onmessage = async (m) => {
    const e = JSON.parse(m.data);
    if (e.type === "build") {
      // The structures built for a comparison or the benchmark have their own status lines there:
      // this one is the current structure's, and keeps its last word until the next rebuild.
      if (e.state === "running" && e.purpose === "current") $("build-status").textContent = `building ${e.kind}: ${(e.elapsed_ms / 1000).toFixed(1)} s`;
      if (e.state === "failed") $("build-status").textContent = `build of ${e.kind} failed: ${e.error}`;
      if (e.state === "done") { showStats(e.stats, false); $("build-status").textContent = `built ${e.kind} in ${e.stats.build_ms.toFixed(1)} ms`; }
    } else if (e.type === "bench") {
      const r = await (await api("/api/bench")).json();
      chart(r.rows);
      $("bench-status").textContent = r.state === "done" ? `done (${r.rows.length} structures, the current view's rays)` : r.state;
    } else if (e.type === "error") {
      status(`render failed: ${e.error}`);
    }
  };
}

async function main() {
  try {
    state.scene = await (await api("/api/scene")).json();
  } catch (e) {
    status(`cannot load the scene: ${e.message}`);
    return;
  }
  $("scene-name").textContent = state.scene.scene;
  state.scene.cameras.forEach((c, i) => $("camera").add(new Option(`${c.id} (${c.width}x${c.height})`, i)));
  for (const sel of ["kind", "compare-a", "compare-b"]) state.scene.kinds.forEach((k) => $(sel).add(new Option(k.kind, k.kind)));
  $("kind").value = state.scene.structure.kind;
  $("compare-a").value = "octree"; $("compare-b").value = "bvh-sah";
  showParams(state.scene.structure.kind, state.scene.structure.params);
  showStats(state.scene.structure.stats, false);
  $("width").value = Math.min(480, state.scene.cameras[0].width);
  setupMouse();
  listen();
  $("camera").onchange = () => resetCamera(Number($("camera").value));
  $("reset").onclick = () => resetCamera(state.camera);
  for (const id of ["integrator", "spp"]) $(id).onchange = requestView;
  $("width").onchange = () => { [state.width, state.height] = viewSize(); sizeView(); requestView(); };
  $("overlay-kind").onchange = () => { applyOverlay(); requestView(); };
  $("depth").oninput = () => { applyOverlay(); if ($("overlay-kind").value === "boxes") requestView(); };
  $("opacity").oninput = applyOverlay;
  $("kind").onchange = () => showParams($("kind").value);
  $("rebuild").onclick = rebuild;
  $("compare").onclick = compare;
  $("bench").onclick = bench;
  applyOverlay();
  resetCamera(0);
  follow("render");
  follow("overlay");
}

main();
