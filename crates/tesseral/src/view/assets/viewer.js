// tesseral view: the page's drawing and controls. It uploads the packed octree
// (decoded by tree.js) as a texture and draws it with the fragment shader
// (trace.frag), which casts one ray per pixel through the tree. The camera follows
// `tesseral render` (src/render/mod.rs, Frame::new) so that the first picture
// matches the CPU renderer's.
"use strict";

const VIEWS = { iso: [-45, 35.264389682754654], front: [-90, 0], top: [-90, 90], side: [0, 0] };
const ROW = 4096; // texels per texture row

// ---- State and camera ----------------------------------------------------

const state = {
  frame: 0, azimuth: VIEWS.iso[0], elevation: VIEWS.iso[1], zoom: 1, pan: [0, 0],
  perspective: false, fov: 40, outline: false, shadows: false,
  cut: false, cutAxis: 2, cutAt: Math.round((FIT[0][2] + FIT[1][2]) / 2), keepAbove: false,
  slice: false, sliceAxis: 2, sliceAt: Math.floor((FIT[0][2] + FIT[1][2] - 1) / 2),
  background: [250, 250, 252],
};

const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const normalize = (a) => scale(a, 1 / Math.sqrt(dot(a, a)));
const rad = (deg) => (deg * Math.PI) / 180;

// The camera of src/render/mod.rs (Frame::new) for a w x h picture.
function camera(w, h) {
  const [lo, hi] = FIT;
  let centre = [0, 1, 2].map((a) => (lo[a] + hi[a]) / 2);
  const radius = Math.sqrt([0, 1, 2].reduce((s, a) => s + (hi[a] - lo[a]) ** 2, 0)) / 2;
  let az = rad(state.azimuth), el = rad(state.elevation);
  if (state.slice) [az, el] = slicedView(state.sliceAxis).map(rad);
  const toCam = [Math.cos(el) * Math.cos(az), Math.cos(el) * Math.sin(az), Math.sin(el)];
  const forward = scale(toCam, -1);
  const sgn = Math.sin(el) >= 0 ? 1 : -1;
  const worldUp = Math.abs(Math.cos(el)) < 1e-6 ? [-Math.cos(az) * sgn, -Math.sin(az) * sgn, 0] : [0, 0, 1];
  const right = normalize(cross(forward, worldUp));
  const up = cross(right, forward);
  const aspect = w / Math.max(h, 1);
  const zoom = state.zoom > 0 ? state.zoom : 1;
  let halfH, eye;
  if (!state.perspective) {
    halfH = (radius * 1.05) / zoom / Math.min(aspect, 1);
    centre = add(centre, add(scale(right, state.pan[0] * halfH), scale(up, state.pan[1] * halfH)));
    eye = add(centre, scale(toCam, radius * 3));
  } else {
    const fov = rad(Math.min(Math.max(state.fov, 1), 170));
    const tan = Math.tan(fov / 2);
    const fit = (radius * 1.05) / Math.min(Math.sin(fov / 2), Math.sin(Math.atan(tan * aspect)));
    halfH = tan;
    const panScale = (fit / zoom) * tan;
    centre = add(centre, add(scale(right, state.pan[0] * panScale), scale(up, state.pan[1] * panScale)));
    eye = add(centre, scale(toCam, fit / zoom));
  }
  const light = normalize(add(add(scale(toCam, 0.6), scale(right, -0.45)), [0, 0, 0.9]));
  return { eye, forward, right, up, half: [halfH * aspect, halfH], light, radius };
}

// A slice is seen straight on: z from the top, y from the front, x from the side.
function slicedView(axis) {
  return [VIEWS.side, VIEWS.front, VIEWS.top][axis];
}

// The ray through canvas pixel (x, y), counted from the top-left corner.
function pixelRay(cam, w, h, x, y) {
  const sx = ((x + 0.5) / w) * 2 - 1, sy = 1 - ((y + 0.5) / h) * 2;
  const offset = add(scale(cam.right, sx * cam.half[0]), scale(cam.up, sy * cam.half[1]));
  if (state.perspective) return { o: cam.eye, d: normalize(add(cam.forward, offset)) };
  return { o: add(cam.eye, offset), d: cam.forward };
}

// The kept box of the current frame, local voxels.
function keptBox(frame) {
  const side = 2 ** frame.depth;
  const lo = [0, 0, 0], hi = [side, side, side];
  if (state.slice) {
    const a = state.sliceAxis;
    lo[a] = state.sliceAt - frame.origin[a];
    hi[a] = lo[a] + 1;
  } else if (state.cut) {
    const a = state.cutAxis;
    if (state.keepAbove) lo[a] = state.cutAt - frame.origin[a];
    else hi[a] = state.cutAt - frame.origin[a];
  }
  return [lo, hi];
}

// ---- WebGL ----------------------------------------------------------------

const canvas = document.getElementById("view");
const gl = canvas.getContext("webgl2", { preserveDrawingBuffer: true, antialias: false });

function fail(message) {
  const div = document.createElement("div");
  div.id = "error";
  div.textContent = message;
  document.body.appendChild(div);
  window.tesseral = { ready: false, error: message };
  throw new Error(message);
}
if (!gl) fail("This page needs WebGL2, which this browser does not offer.");

function compile(type, id) {
  const sh = gl.createShader(type);
  gl.shaderSource(sh, document.getElementById(id).textContent.trim());
  gl.compileShader(sh);
  if (!gl.getShaderParameter(sh, gl.COMPILE_STATUS)) fail(id + ": " + gl.getShaderInfoLog(sh));
  return sh;
}
const program = gl.createProgram();
gl.attachShader(program, compile(gl.VERTEX_SHADER, "quad-vert"));
gl.attachShader(program, compile(gl.FRAGMENT_SHADER, "trace-frag"));
gl.linkProgram(program);
if (!gl.getProgramParameter(program, gl.LINK_STATUS)) fail(gl.getProgramInfoLog(program));
gl.useProgram(program);
gl.bindVertexArray(gl.createVertexArray());
const U = {};
for (let i = 0; i < gl.getProgramParameter(program, gl.ACTIVE_UNIFORMS); i++) {
  const name = gl.getActiveUniform(program, i).name;
  U[name] = gl.getUniformLocation(program, name);
}

function texture(unit, internal, format, type, data, texels, perTexel) {
  const rows = Math.max(1, Math.ceil(texels / ROW));
  if (rows > gl.getParameter(gl.MAX_TEXTURE_SIZE)) fail("The tree is too large for this GPU's textures.");
  const padded = new data.constructor(rows * ROW * perTexel);
  padded.set(data.subarray(0, texels * perTexel));
  const tex = gl.createTexture();
  gl.activeTexture(gl.TEXTURE0 + unit);
  gl.bindTexture(gl.TEXTURE_2D, tex);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  gl.texImage2D(gl.TEXTURE_2D, 0, internal, ROW, rows, 0, format, type, padded);
  for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
  return tex;
}
texture(0, gl.R32UI, gl.RED_INTEGER, gl.UNSIGNED_INT, ENTRIES, ENTRIES.length, 1);
const colours = PALETTE.length / 3;
const rgba = new Uint8Array(Math.max(colours, 1) * 4);
for (let i = 0; i < colours; i++) rgba.set([PALETTE[3 * i], PALETTE[3 * i + 1], PALETTE[3 * i + 2], 255], 4 * i);
texture(1, gl.RGBA8, gl.RGBA, gl.UNSIGNED_BYTE, rgba, Math.max(colours, 1), 4);
gl.uniform1i(U.uTree, 0);
gl.uniform1i(U.uPalette, 1);

function resize() {
  const dpr = window.devicePixelRatio || 1;
  const w = Math.max(1, Math.round(canvas.clientWidth * dpr));
  const h = Math.max(1, Math.round(canvas.clientHeight * dpr));
  if (canvas.width !== w || canvas.height !== h) {
    canvas.width = w;
    canvas.height = h;
  }
}

function draw() {
  resize();
  const w = canvas.width, h = canvas.height;
  const frame = DATA.frames[state.frame];
  const cam = camera(w, h);
  const [lo, hi] = keptBox(frame);
  gl.viewport(0, 0, w, h);
  gl.uniform1ui(U.uRoot, frame.root);
  gl.uniform1i(U.uDepth, frame.depth);
  gl.uniform1i(U.uEmpty, frame.empty ? 1 : 0);
  gl.uniform3fv(U.uOrigin, frame.origin);
  gl.uniform3iv(U.uLo, lo);
  gl.uniform3iv(U.uHi, hi);
  gl.uniform1i(U.uCutAxis, state.cut && !state.slice ? state.cutAxis : -1);
  gl.uniform2f(U.uResolution, w, h);
  // The eye in the tree's local voxels, subtracted here in double precision.
  gl.uniform3fv(U.uEye, cam.eye.map((c, a) => c - frame.origin[a]));
  gl.uniform3fv(U.uForward, cam.forward);
  gl.uniform3fv(U.uRight, cam.right);
  gl.uniform3fv(U.uUp, cam.up);
  gl.uniform2fv(U.uHalf, cam.half);
  gl.uniform1i(U.uPerspective, state.perspective ? 1 : 0);
  gl.uniform3fv(U.uLight, cam.light);
  gl.uniform1i(U.uOutline, state.outline || state.slice ? 1 : 0);
  gl.uniform1i(U.uShadows, state.shadows ? 1 : 0);
  gl.uniform3fv(U.uBackground, state.background);
  gl.drawArrays(gl.TRIANGLES, 0, 3);
}

let pending = false;
function redraw() {
  if (pending) return;
  pending = true;
  requestAnimationFrame(() => {
    pending = false;
    draw();
  });
}

// ---- Panel -----------------------------------------------------------------

const $ = (id) => document.getElementById(id);
$("title").textContent = DATA.title;
for (const note of DATA.notes) {
  const p = document.createElement("p");
  p.textContent = note;
  $("notes").appendChild(p);
}

const fmt = (x) => (Number.isInteger(x) ? x.toLocaleString("en-US") : x.toPrecision(6).replace(/\.?0+$/, ""));
const world = (v) => v.map((c, a) => DATA.translate[a] + DATA.voxel_size * c);
const triple = (v) => "(" + v.map(fmt).join(", ") + ")";

let hover = null; // what is under the cursor: the hit, or null
let kept = null; // black voxels kept by the cut, once counted

function infoRows() {
  const f = DATA.frames[state.frame];
  const rows = [
    ["voxels", fmt(f.voxels)],
    ["leaves", fmt(f.leaves)],
    ["depth", f.levels < f.depth ? f.depth + " (shown at " + f.levels + ")" : String(f.depth)],
    ["frame", "voxel " + fmt(DATA.voxel_size) + ", origin " + triple(DATA.translate)],
  ];
  if (f.bbox) {
    const hi = f.bbox[1].map((c) => c + 1);
    rows.push(["bbox", "voxels " + triple(f.bbox[0]) + " to " + triple(hi)]);
    rows.push(["", "world " + triple(world(f.bbox[0])) + " to " + triple(world(hi))]);
  } else {
    rows.push(["bbox", "empty"]);
  }
  if (state.cut && !state.slice) rows.push(["kept", kept === null ? "counting..." : fmt(kept) + " voxels"]);
  if (state.slice) rows.push(["slice", "xyz"[state.sliceAxis] + " = " + state.sliceAt]);
  if (DATA.frames.length > 1) rows.push(["time", (state.frame + 1) + " of " + DATA.frames.length + ": " + f.label]);
  if (hover) {
    const centre = hover.abs.map((c) => c + 0.5);
    rows.push(["cursor", "voxel " + triple(hover.abs)]);
    rows.push(["", "world " + triple(world(centre))]);
  } else {
    rows.push(["cursor", "-"]);
  }
  return rows;
}

function showInfo() {
  const table = $("info");
  table.textContent = "";
  for (const [k, v] of infoRows()) {
    const tr = table.insertRow();
    tr.insertCell().textContent = k;
    tr.insertCell().textContent = v;
  }
}

let countTimer = 0;
function recount() {
  kept = null;
  clearTimeout(countTimer);
  if (state.cut && !state.slice) {
    countTimer = setTimeout(() => {
      const f = DATA.frames[state.frame];
      const [lo, hi] = keptBox(f);
      kept = countInBox(f, lo, hi);
      showInfo();
    }, 120);
  }
}

function syncControls() {
  const f = DATA.frames[state.frame];
  $("outline").checked = state.outline;
  $("shadows").checked = state.shadows;
  $("perspective").checked = state.perspective;
  $("cut").checked = state.cut;
  $("cut-axis").value = String(state.cutAxis);
  $("cut-side").value = state.keepAbove ? "above" : "below";
  const ca = state.cutAxis;
  $("cut-at").min = FIT[0][ca];
  $("cut-at").max = FIT[1][ca];
  $("cut-at").value = state.cutAt;
  $("cut-value").textContent = "xyz"[ca] + (state.keepAbove ? " \u2265 " : " < ") + state.cutAt;
  $("slice").checked = state.slice;
  $("slice-axis").value = String(state.sliceAxis);
  const sa = state.sliceAxis;
  $("slice-at").min = f.origin[sa];
  $("slice-at").max = f.origin[sa] + 2 ** f.depth - 1;
  $("slice-at").value = state.sliceAt;
  $("slice-value").textContent = "xyz"[sa] + " = " + state.sliceAt;
  $("time-row").style.display = DATA.frames.length > 1 ? "" : "none";
  $("time").max = DATA.frames.length - 1;
  $("time").value = state.frame;
  $("time-label").textContent = f.label;
}

// Changes the state, then redraws and refreshes the panel.
function set(changes) {
  const cutChanged = ["cut", "cutAxis", "cutAt", "keepAbove", "frame", "slice"].some((k) => k in changes);
  if ("cutAxis" in changes && !("cutAt" in changes)) {
    const a = changes.cutAxis;
    changes.cutAt = Math.round((FIT[0][a] + FIT[1][a]) / 2);
  }
  if ("sliceAxis" in changes && !("sliceAt" in changes)) {
    const a = changes.sliceAxis;
    changes.sliceAt = Math.floor((FIT[0][a] + FIT[1][a] - 1) / 2);
  }
  Object.assign(state, changes);
  state.elevation = Math.max(-90, Math.min(90, state.elevation));
  if (cutChanged) recount();
  syncControls();
  showInfo();
  redraw();
}

function setView(name) {
  const [azimuth, elevation] = VIEWS[name];
  set({ azimuth, elevation, zoom: 1, pan: [0, 0], slice: false });
}

for (const b of document.querySelectorAll("#views button")) b.onclick = () => setView(b.dataset.view);
$("outline").onchange = (e) => set({ outline: e.target.checked });
$("shadows").onchange = (e) => set({ shadows: e.target.checked });
$("perspective").onchange = (e) => set({ perspective: e.target.checked, pan: [0, 0] });
$("cut").onchange = (e) => set({ cut: e.target.checked });
$("cut-axis").onchange = (e) => set({ cutAxis: Number(e.target.value), cut: true });
$("cut-side").onchange = (e) => set({ keepAbove: e.target.value === "above", cut: true });
$("cut-at").oninput = (e) => set({ cutAt: Number(e.target.value), cut: true });
$("slice").onchange = (e) => set({ slice: e.target.checked });
$("slice-axis").onchange = (e) => set({ sliceAxis: Number(e.target.value), slice: true });
$("slice-at").oninput = (e) => set({ sliceAt: Number(e.target.value), slice: true });
$("time").oninput = (e) => set({ frame: Number(e.target.value) });
let playing = 0;
$("play").onclick = () => {
  if (playing) {
    clearInterval(playing);
    playing = 0;
    $("play").textContent = "play";
    return;
  }
  $("play").textContent = "stop";
  playing = setInterval(() => set({ frame: (state.frame + 1) % DATA.frames.length }), 200);
};

// ---- Mouse, touch and keys -------------------------------------------------

const pointers = new Map();
let drag = null;

function pick(x, y) {
  const w = canvas.width, h = canvas.height;
  const f = DATA.frames[state.frame];
  const cam = camera(w, h);
  const ray = pixelRay(cam, w, h, x, y);
  const o = ray.o.map((c, a) => c - f.origin[a]);
  const [lo, hi] = keptBox(f);
  const hit = cast(f, o, ray.d, lo, hi);
  if (!hit) return null;
  return { voxel: hit.voxel, abs: hit.voxel.map((c, a) => c + f.origin[a]), t: hit.t, axis: hit.axis,
    colour: Array.from(PALETTE.subarray(3 * hit.cell.colour, 3 * hit.cell.colour + 3)) };
}

function canvasXY(e) {
  const r = canvas.getBoundingClientRect();
  return [((e.clientX - r.left) * canvas.width) / r.width, ((e.clientY - r.top) * canvas.height) / r.height];
}

canvas.addEventListener("contextmenu", (e) => e.preventDefault());
canvas.addEventListener("pointerdown", (e) => {
  canvas.setPointerCapture(e.pointerId);
  pointers.set(e.pointerId, [e.clientX, e.clientY]);
  const mode = e.button === 2 || e.shiftKey ? "pan" : e.ctrlKey && state.cut ? "cut" : "orbit";
  drag = { mode, x: e.clientX, y: e.clientY };
});
canvas.addEventListener("pointerup", (e) => {
  pointers.delete(e.pointerId);
  drag = pointers.size ? { mode: "orbit", x: [...pointers.values()][0][0], y: [...pointers.values()][0][1] } : null;
});
canvas.addEventListener("pointercancel", (e) => {
  pointers.delete(e.pointerId);
  drag = null;
});
canvas.addEventListener("pointermove", (e) => {
  if (!drag) {
    const [x, y] = canvasXY(e);
    hover = pick(x, y);
    showInfo();
    return;
  }
  const before = [...pointers.values()];
  pointers.set(e.pointerId, [e.clientX, e.clientY]);
  const h = canvas.clientHeight;
  if (pointers.size === 2) {
    // Two fingers: pinch to zoom, move together to pan.
    const after = [...pointers.values()];
    const dist = (p) => Math.hypot(p[0][0] - p[1][0], p[0][1] - p[1][1]);
    const mid = (p) => [(p[0][0] + p[1][0]) / 2, (p[0][1] + p[1][1]) / 2];
    if (before.length === 2) {
      const k = dist(after) / Math.max(dist(before), 1);
      const [m0, m1] = [mid(before), mid(after)];
      set({ zoom: state.zoom * k, pan: [state.pan[0] - ((m1[0] - m0[0]) * 2) / h, state.pan[1] + ((m1[1] - m0[1]) * 2) / h] });
    }
    return;
  }
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  drag.x = e.clientX;
  drag.y = e.clientY;
  if (drag.mode === "orbit") {
    set({ azimuth: state.azimuth - dx * 0.4, elevation: state.elevation + dy * 0.4, slice: false });
  } else if (drag.mode === "pan") {
    set({ pan: [state.pan[0] - (dx * 2) / h, state.pan[1] + (dy * 2) / h] });
  } else {
    const a = state.cutAxis;
    const span = FIT[1][a] - FIT[0][a];
    drag.acc = (drag.acc || 0) - (dy * span) / h;
    const step = Math.trunc(drag.acc);
    if (step) {
      drag.acc -= step;
      set({ cutAt: Math.max(FIT[0][a], Math.min(FIT[1][a], state.cutAt + step)) });
    }
  }
});
canvas.addEventListener("wheel", (e) => {
  e.preventDefault();
  set({ zoom: state.zoom * Math.exp(-e.deltaY * 0.001) });
}, { passive: false });
window.addEventListener("keydown", (e) => {
  if (e.target.tagName === "INPUT" || e.target.tagName === "SELECT") return;
  const views = { 1: "iso", 2: "front", 3: "top", 4: "side" };
  if (views[e.key]) setView(views[e.key]);
  else if (e.key === "o") set({ outline: !state.outline });
  else if (e.key === "c") set({ cut: !state.cut });
  else if (e.key === "s") set({ slice: !state.slice });
  else if (e.key === "h") $("panel").classList.toggle("hidden");
});
window.addEventListener("resize", redraw);

// ---- For scripts and tests --------------------------------------------------

// Draws n frames and waits for the GPU each time: milliseconds per frame.
function bench(n) {
  const px = new Uint8Array(4);
  draw();
  gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
  const start = performance.now();
  for (let i = 0; i < n; i++) {
    draw();
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
  }
  return (performance.now() - start) / n;
}

window.tesseral = {
  ready: true,
  loadMs: performance.now(),
  state,
  set,
  setView,
  pick,
  bench,
  info: () => Object.fromEntries(infoRows().filter((r) => r[0])),
  kept: () => {
    const f = DATA.frames[state.frame];
    const [lo, hi] = keptBox(f);
    return countInBox(f, lo, hi);
  },
  draw,
  // Fixes the canvas at w x h CSS pixels (tests compare it with a PNG of that size).
  setSize: (w, h) => {
    canvas.style.width = w + "px";
    canvas.style.height = h + "px";
    draw();
  },
  snapshot: () => {
    draw();
    return canvas.toDataURL("image/png");
  },
};
syncControls();
showInfo();
recount();
draw();
