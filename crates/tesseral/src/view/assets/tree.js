// tesseral view: the page's data and its walk of the packed tree. It decodes the
// JSON block (entries and palette, base64) and walks the tree as trace.frag does
// on the GPU and src/view/trace.rs in Rust: for picking the voxel under the cursor
// and counting the voxels a cut keeps. viewer.js (loaded after it) draws.
"use strict";

const DATA = JSON.parse(document.getElementById("tesseral-data").textContent);
const MAX_STEPS = 2048; // the most white cells a ray crosses (as the shader)

// ---- Data ---------------------------------------------------------------

function decodeBase64(text) {
  const bin = atob(text);
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
  return out;
}

const entryBytes = decodeBase64(DATA.entries);
const ENTRIES = new Uint32Array(entryBytes.buffer, 0, DATA.entry_count);
const PALETTE = decodeBase64(DATA.palette);

// The box around every frame's black voxels (absolute voxels, upper bound
// exclusive); the space of the first frame when all are empty.
function fitBox() {
  let lo = null, hi = null;
  for (const f of DATA.frames) {
    if (!f.bbox) continue;
    const [a, b] = f.bbox;
    lo = lo ? lo.map((v, i) => Math.min(v, a[i])) : a.slice();
    hi = hi ? hi.map((v, i) => Math.max(v, b[i] + 1)) : b.map((v) => v + 1);
  }
  if (!lo) {
    const f = DATA.frames[0];
    lo = f.origin.slice();
    hi = f.origin.map((v) => v + 2 ** f.depth);
  }
  return [lo, hi];
}
const FIT = fitBox();

// ---- The packed tree, walked in JavaScript (as trace.frag and trace.rs) ---

function popcount(x) {
  x = x - ((x >>> 1) & 0x55);
  x = (x & 0x33) + ((x >>> 2) & 0x33);
  return (x + (x >>> 4)) & 0x0f;
}

// The cell holding local voxel v: {colour (-1 white), min, size}.
function lookup(frame, v) {
  let s = frame.depth;
  if (frame.empty) return { colour: -1, min: [0, 0, 0], size: 2 ** s };
  let e = ENTRIES[frame.root];
  for (;;) {
    const mask = e & 255;
    if (mask === 0) {
      const size = 2 ** s;
      return { colour: e >>> 8, min: v.map((c) => Math.floor(c / size) * size), size };
    }
    s -= 1;
    const size = 2 ** s;
    const bit = (a) => Math.floor(v[a] / size) & 1;
    const d = bit(0) | (bit(1) << 1) | (bit(2) << 2);
    if ((mask & (1 << d)) === 0) {
      return { colour: -1, min: v.map((c) => Math.floor(c / size) * size), size };
    }
    e = ENTRIES[(e >>> 8) + popcount(mask & ((1 << d) - 1))];
  }
}

// The first black voxel along o + t d inside the local box [lo, hi), or null.
function cast(frame, o, d, lo, hi) {
  const side = 2 ** frame.depth;
  lo = lo.map((c) => Math.max(c, 0));
  hi = hi.map((c) => Math.min(c, side));
  if ([0, 1, 2].some((a) => lo[a] >= hi[a])) return null;
  let t0 = 0, t1 = Infinity, axis = 0;
  for (let a = 0; a < 3; a++) {
    if (d[a] === 0) {
      if (o[a] < lo[a] || o[a] > hi[a]) return null;
      continue;
    }
    const ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
    const tn = Math.min(ta, tb), tf = Math.max(ta, tb);
    if (tn > t0) { t0 = tn; axis = a; }
    t1 = Math.min(t1, tf);
  }
  if (t0 >= t1) return null;
  const c = [0, 1, 2].map((a) => Math.min(Math.max(Math.floor(o[a] + d[a] * t0), lo[a]), hi[a] - 1));
  for (let step = 0; step < MAX_STEPS; step++) {
    const cell = lookup(frame, c);
    if (cell.colour >= 0) return { t: t0, axis, voxel: c.slice(), cell };
    const exit = [0, 1, 2].map((a) =>
      d[a] > 0 ? (cell.min[a] + cell.size - o[a]) / d[a] : d[a] < 0 ? (cell.min[a] - o[a]) / d[a] : Infinity);
    const tn = Math.min(exit[0], exit[1], exit[2]);
    for (let a = 0; a < 3; a++) {
      if (exit[a] <= tn) {
        axis = a;
        c[a] = d[a] > 0 ? cell.min[a] + cell.size : cell.min[a] - 1;
      } else {
        c[a] = Math.min(Math.max(Math.floor(o[a] + d[a] * tn), cell.min[a]), cell.min[a] + cell.size - 1);
      }
    }
    t0 = tn;
    if ([0, 1, 2].some((a) => c[a] < lo[a] || c[a] >= hi[a])) return null;
  }
  return null;
}

// The black voxels of the shown tree inside the local box [lo, hi).
function countInBox(frame, lo, hi) {
  if (frame.empty) return 0;
  function walk(e, min, s) {
    const size = 2 ** s;
    let vol = 1;
    for (let a = 0; a < 3; a++) {
      const span = Math.min(min[a] + size, hi[a]) - Math.max(min[a], lo[a]);
      if (span <= 0) return 0;
      vol *= span;
    }
    const mask = e & 255;
    if (mask === 0) return vol;
    const half = size / 2;
    let sum = 0;
    for (let d = 0; d < 8; d++) {
      if ((mask & (1 << d)) === 0) continue;
      const child = ENTRIES[(e >>> 8) + popcount(mask & ((1 << d) - 1))];
      sum += walk(child, [min[0] + (d & 1) * half, min[1] + ((d >> 1) & 1) * half, min[2] + ((d >> 2) & 1) * half], s - 1);
    }
    return sum;
  }
  return walk(ENTRIES[frame.root], [0, 0, 0], frame.depth);
}
