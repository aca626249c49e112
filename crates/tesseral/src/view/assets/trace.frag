#version 300 es
// Casts one ray per pixel through the packed octree (see docs/view.md and
// src/view/trace.rs, which does the same walk in Rust for the tests).
//
// Entry = mask (low 8 bits) | payload << 8. mask != 0: a grey node whose children
// start at entry `payload`, child d at payload + popcount(mask & ((1 << d) - 1));
// mask == 0: a black leaf of colour `payload`. White children have no entry.
precision highp float;
precision highp int;
precision highp usampler2D;

uniform usampler2D uTree;    // entries, 4096 per row
uniform sampler2D uPalette;  // colours, 4096 per row
uniform uint uRoot;
uniform int uDepth;
uniform bool uEmpty;
uniform vec3 uOrigin;        // the tree's lowest voxel (absolute voxels)
uniform ivec3 uLo;           // the box kept by cut or slice, voxels from uOrigin
uniform ivec3 uHi;
uniform int uCutAxis;        // -1: no cut; else the axis of the cut plane
uniform vec2 uResolution;
uniform vec3 uEye;          // the eye, voxels from uOrigin
uniform vec3 uForward;
uniform vec3 uRight;
uniform vec3 uUp;
uniform vec2 uHalf;          // half width and height of the view (voxels, or tan)
uniform bool uPerspective;
uniform vec3 uLight;
uniform bool uOutline;
uniform bool uShadows;
uniform vec3 uBackground;

out vec4 fragColor;

const int MAX_STEPS = 2048;

uint entry(uint i) {
  return texelFetch(uTree, ivec2(int(i & 4095u), int(i >> 12u)), 0).r;
}

// The set bits of an 8-bit mask (GLSL ES 3.00 has no bitCount).
uint popcount8(uint x) {
  x = x - ((x >> 1u) & 0x55u);
  x = (x & 0x33u) + ((x >> 2u) & 0x33u);
  return (x + (x >> 4u)) & 0x0fu;
}

// The cell holding voxel v: its colour (or -1 when white), lowest voxel and size.
int lookupCell(ivec3 v, out ivec3 cmin, out int s) {
  s = uDepth;
  cmin = ivec3(0);
  if (uEmpty) return -1;
  uint e = entry(uRoot);
  for (int k = 0; k < 24; k++) {
    uint mask = e & 255u;
    if (mask == 0u) {
      cmin = (v >> s) << s;
      return int(e >> 8u);
    }
    s -= 1;
    ivec3 b = (v >> s) & 1;
    uint d = uint(b.x | (b.y << 1) | (b.z << 2));
    if ((mask & (1u << d)) == 0u) {
      cmin = (v >> s) << s;
      return -1;
    }
    e = entry((e >> 8u) + popcount8(mask & ((1u << d) - 1u)));
  }
  return -1;
}

struct Hit {
  float t;
  int axis;
  ivec3 voxel;
  ivec3 cmin;
  int size;
  int colour;
};

// The first black voxel along o + t d (t >= 0) inside the voxels [lo, hi).
bool castRay(vec3 o, vec3 d, ivec3 lo, ivec3 hi, out Hit h) {
  int side = 1 << uDepth;
  lo = max(lo, ivec3(0));
  hi = min(hi, ivec3(side));
  h.t = 0.0; h.axis = 0; h.voxel = ivec3(0); h.cmin = ivec3(0); h.size = 0; h.colour = -1;
  if (any(greaterThanEqual(lo, hi))) return false;
  float t0 = 0.0, t1 = 1e30;
  int axis = 0;
  for (int a = 0; a < 3; a++) {
    float l = float(lo[a]), u = float(hi[a]);
    if (d[a] == 0.0) {
      if (o[a] < l || o[a] > u) return false;
      continue;
    }
    float ta = (l - o[a]) / d[a], tb = (u - o[a]) / d[a];
    float tn = min(ta, tb), tf = max(ta, tb);
    if (tn > t0) { t0 = tn; axis = a; }
    t1 = min(t1, tf);
  }
  if (t0 >= t1) return false;
  ivec3 c = clamp(ivec3(floor(o + d * t0)), lo, hi - 1);
  for (int step = 0; step < MAX_STEPS; step++) {
    ivec3 cmin;
    int s;
    int colour = lookupCell(c, cmin, s);
    if (colour >= 0) {
      h.t = t0; h.axis = axis; h.voxel = c; h.cmin = cmin; h.size = 1 << s; h.colour = colour;
      return true;
    }
    int size = 1 << s;
    vec3 exit = vec3(1e30);
    for (int a = 0; a < 3; a++) {
      if (d[a] > 0.0) exit[a] = (float(cmin[a] + size) - o[a]) / d[a];
      else if (d[a] < 0.0) exit[a] = (float(cmin[a]) - o[a]) / d[a];
    }
    float tn = min(exit.x, min(exit.y, exit.z));
    for (int a = 0; a < 3; a++) {
      if (exit[a] <= tn) {
        axis = a;
        c[a] = d[a] > 0.0 ? cmin[a] + size : cmin[a] - 1;
      } else {
        c[a] = clamp(int(floor(o[a] + d[a] * tn)), cmin[a], cmin[a] + size - 1);
      }
    }
    t0 = tn;
    if (any(lessThan(c, lo)) || any(greaterThanEqual(c, hi))) return false;
  }
  return false;
}

vec3 paletteColour(int i) {
  return texelFetch(uPalette, ivec2(i & 4095, i >> 12), 0).rgb * 255.0;
}

void main() {
  vec2 s = gl_FragCoord.xy / uResolution * 2.0 - 1.0;
  vec3 o, d;
  if (uPerspective) {
    o = uEye;
    d = normalize(uForward + uRight * (s.x * uHalf.x) + uUp * (s.y * uHalf.y));
  } else {
    o = uEye + uRight * (s.x * uHalf.x) + uUp * (s.y * uHalf.y);
    d = uForward;
  }
  vec3 ol = o;
  Hit h;
  if (!castRay(ol, d, uLo, uHi, h)) {
    fragColor = vec4(uBackground / 255.0, 1.0);
    return;
  }
  vec3 p = ol + d * h.t;
  vec3 n = vec3(0.0);
  n[h.axis] = d[h.axis] > 0.0 ? -1.0 : 1.0;
  vec3 base = paletteColour(h.colour);
  // A cut face: on the cut plane, where the part removed was black too.
  bool cut = false;
  if (uCutAxis >= 0 && h.axis == uCutAxis) {
    int a = uCutAxis;
    bool onLo = h.voxel[a] == uLo[a] && n[a] < 0.0;
    bool onHi = h.voxel[a] == uHi[a] - 1 && n[a] > 0.0;
    if (onLo || onHi) {
      ivec3 beyond = h.voxel;
      beyond[a] += onHi ? 1 : -1;
      ivec3 cm;
      int sz;
      cut = beyond[a] >= 0 && beyond[a] < (1 << uDepth) && lookupCell(beyond, cm, sz) >= 0;
    }
  }
  if (cut) {
    vec3 w = p + uOrigin;
    bool stripe = mod((w.x + w.y + w.z) / 3.0, 6.0) < 3.0;
    base = floor(base * (stripe ? 0.55 : 0.7));
  }
  float light = max(dot(n, uLight), 0.0);
  if (uShadows && light > 0.0) {
    Hit sh;
    if (castRay(p + n * 1e-3, uLight, uLo, uHi, sh)) light = 0.0;
  }
  float k = min(0.42 + 0.62 * light + 0.12 * max(dot(n, -uForward), 0.0), 1.15);
  vec3 rgb = min(base * k, vec3(255.0));
  if (uOutline) {
    float edge = 1e30;
    for (int a = 0; a < 3; a++) {
      if (a == h.axis && !cut) continue;
      if (cut && a == uCutAxis) continue;
      float u = p[a] - float(h.cmin[a]);
      edge = min(edge, min(abs(u), abs(float(h.size) - u)));
    }
    float pixel = 2.0 * uHalf.y / uResolution.y * (uPerspective ? h.t : 1.0);
    if (edge < pixel * 0.75) rgb *= 0.25;
  }
  fragColor = vec4(floor(rgb + 0.5) / 255.0, 1.0);
}
