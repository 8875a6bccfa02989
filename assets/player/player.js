"use strict";
// formation's 3-D player: WebGL 2, no library. Data and layout in docs/player.md.
(function () {
  const $ = id => document.getElementById(id);
  const t0 = performance.now();
  const M = JSON.parse($("fp-meta").textContent), FOLD = JSON.parse($("fp-fold").textContent);
  function b64(id) {
    const s = $(id).textContent.trim();
    if (Uint8Array.fromBase64) return Uint8Array.fromBase64(s);
    const bin = atob(s), u = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) u[i] = bin.charCodeAt(i);
    return u;
  }
  const u8 = b64("fp-pos"), POS = new Float32Array(u8.buffer, 0, u8.byteLength >> 2);
  const h8 = b64("fp-hdg"), HDG = new Int16Array(h8.buffer, 0, h8.byteLength >> 1);
  const i8 = b64("fp-i8"), I8 = new Int8Array(i8.buffer, 0, i8.byteLength);
  const e8 = b64("fp-e"), E = new Int16Array(e8.buffer, 0, e8.byteLength >> 1);
  const o8 = b64("fp-total"), TOT = new Int16Array(o8.buffer, 0, o8.byteLength >> 1);
  const B = M.birds, F = M.frames, SC = M.scales, T = M.times;
  const ui = $("fp-ui"), cv = $("fp-canvas");
  const fail = msg => { ui.innerHTML = "<b>This page needs WebGL 2:</b> " + msg; window.formationPlayer = { ready: false, error: msg }; };
  const gl = cv.getContext("webgl2", { antialias: true });
  if (!gl) { fail("the browser gave no WebGL 2 context."); return; }
  // ---- small maths ----
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]], dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const norm = a => { const l = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / l, a[1] / l, a[2] / l]; };
  function mul(a, b) { const o = new Float32Array(16); for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++) { let s = 0; for (let k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k]; o[c * 4 + r] = s; } return o; }
  function persp(fov, asp, n, f) { const t = 1 / Math.tan(fov / 2); return new Float32Array([t / asp, 0, 0, 0, 0, t, 0, 0, 0, 0, (f + n) / (n - f), -1, 0, 0, 2 * f * n / (n - f), 0]); }
  function look(e, c, up) { const z = norm(sub(e, c)), x = norm(cross(up, z)), y = cross(z, x); return new Float32Array([x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0, -dot(x, e), -dot(y, e), -dot(z, e), 1]); }
  function inv(m) { // general 4x4 inverse
    const r = new Float32Array(16), [a00, a01, a02, a03, a10, a11, a12, a13, a20, a21, a22, a23, a30, a31, a32, a33] = m;
    const b00 = a00 * a11 - a01 * a10, b01 = a00 * a12 - a02 * a10, b02 = a00 * a13 - a03 * a10, b03 = a01 * a12 - a02 * a11, b04 = a01 * a13 - a03 * a11, b05 = a02 * a13 - a03 * a12;
    const b06 = a20 * a31 - a21 * a30, b07 = a20 * a32 - a22 * a30, b08 = a20 * a33 - a23 * a30, b09 = a21 * a32 - a22 * a31, b10 = a21 * a33 - a23 * a31, b11 = a22 * a33 - a23 * a32;
    const d = 1 / (b00 * b11 - b01 * b10 + b02 * b09 + b03 * b08 - b04 * b07 + b05 * b06);
    r[0] = (a11 * b11 - a12 * b10 + a13 * b09) * d; r[1] = (a02 * b10 - a01 * b11 - a03 * b09) * d; r[2] = (a31 * b05 - a32 * b04 + a33 * b03) * d; r[3] = (a22 * b04 - a21 * b05 - a23 * b03) * d;
    r[4] = (a12 * b08 - a10 * b11 - a13 * b07) * d; r[5] = (a00 * b11 - a02 * b08 + a03 * b07) * d; r[6] = (a32 * b02 - a30 * b05 - a33 * b01) * d; r[7] = (a20 * b05 - a22 * b02 + a23 * b01) * d;
    r[8] = (a10 * b10 - a11 * b08 + a13 * b06) * d; r[9] = (a01 * b08 - a00 * b10 - a03 * b06) * d; r[10] = (a30 * b04 - a31 * b02 + a33 * b00) * d; r[11] = (a21 * b02 - a20 * b04 - a23 * b00) * d;
    r[12] = (a11 * b07 - a10 * b09 - a12 * b06) * d; r[13] = (a00 * b09 - a01 * b07 + a02 * b06) * d; r[14] = (a31 * b01 - a30 * b03 - a32 * b00) * d; r[15] = (a20 * b03 - a21 * b01 + a22 * b00) * d;
    return r;
  }
  // ---- shaders ----
  function prog(vs, fs) {
    const p = gl.createProgram();
    for (const [t, s] of [[gl.VERTEX_SHADER, vs], [gl.FRAGMENT_SHADER, fs]]) {
      const sh = gl.createShader(t); gl.shaderSource(sh, "#version 300 es\nprecision highp float;\n" + s); gl.compileShader(sh);
      if (!gl.getShaderParameter(sh, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(sh));
      gl.attachShader(p, sh);
    }
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
    const u = {}; const n = gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS);
    for (let i = 0; i < n; i++) { const nm = gl.getActiveUniform(p, i).name; u[nm] = gl.getUniformLocation(p, nm); }
    return { p, u };
  }
  const ROT = `mat3 rx(float a){float c=cos(a),s=sin(a);return mat3(1.,0.,0.,0.,c,s,0.,-s,c);}
mat3 ry(float a){float c=cos(a),s=sin(a);return mat3(c,0.,-s,0.,1.,0.,s,0.,c);}
mat3 rz(float a){float c=cos(a),s=sin(a);return mat3(c,s,0.,-s,c,0.,0.,0.,1.);}`;
  // Birds: the rig's joint rotations (shoulder R_Y(-s(sweep - fa(1-spread))) R_Z(s dihedral), wrist
  // R_Y(s fh (1-spread)) R_Z(s hand dihedral), written here in the bird frame x right, y forward, z up).
  const birdP = prog(`layout(location=0) in vec3 ap;layout(location=1) in vec3 an;layout(location=2) in vec3 ac;layout(location=3) in vec2 aps;
layout(location=4) in vec4 i0;layout(location=5) in vec4 i1;layout(location=6) in vec4 i2;layout(location=7) in vec4 i3;
uniform mat4 vp;uniform vec4 geo;uniform vec3 hip;out vec3 vn;out vec3 vc;` + ROT + `
void main(){float part=aps.x,s=aps.y;vec3 p=ap,n=an;float fold=1.-clamp(i2.y,0.,1.);
if(part>0.5&&part<2.5){mat3 qs=rz(-s*(i2.x-geo.z*fold))*ry(s*i1.z);vec3 sh=vec3(-s*geo.x,0.,0.);
 if(part>1.5){mat3 qw=rz(s*geo.w*fold)*ry(s*i1.w);p=sh+qs*(vec3(-s*geo.y,0.,0.)+qw*p);n=qs*qw*n;}else{p=sh+qs*p;n=qs*n;}}
else if(part>2.5){p=vec3(ap.x,hip.y-ap.y*cos(i2.z),hip.z-ap.y*sin(i2.z));}
mat3 bd=rz(-i0.w)*rx(i1.y)*ry(i1.x);gl_Position=vp*vec4(i0.xyz+bd*p,1.);vn=bd*n;
vc=mix(ac,i3.rgb,i3.a);if(i2.w>0.5)vc=mix(vc,vec3(1.,.85,0.),.6);}`,
    `in vec3 vn;in vec3 vc;out vec4 o;void main(){vec3 L=normalize(vec3(.3,.4,.85));float d=abs(dot(normalize(vn),L));o=vec4(vc*(.5+.6*d),1.);}`);
  const skyP = prog(`out vec2 q;void main(){vec2 v=vec2(float((gl_VertexID<<1)&2),float(gl_VertexID&2));q=v*2.-1.;gl_Position=vec4(q,.9999,1.);}`,
    `in vec2 q;uniform mat4 ivp;uniform vec3 eye;out vec4 o;void main(){vec4 a=ivp*vec4(q,1.,1.);vec3 d=normalize(a.xyz/a.w-eye);
float e=clamp(d.z,0.,1.);o=vec4(mix(vec3(.80,.88,.95),vec3(.35,.58,.85),pow(e,.6)),1.);}`);
  const grP = prog(`layout(location=0) in vec2 a;uniform mat4 vp;uniform vec3 c;out vec3 w;void main(){w=vec3(c.xy+a*6000.,0.);gl_Position=vp*vec4(w,1.);}`,
    `in vec3 w;uniform vec3 eye;uniform vec3 col;out vec4 o;void main(){vec2 g=w.xy/10.;vec2 f=abs(fract(g-.5)-.5)/fwidth(g);
float l=1.-min(min(f.x,f.y),1.);float d=length(w-eye);vec3 c=mix(col,col*.8,l*.7);o=vec4(mix(c,vec3(.80,.88,.95),1.-exp(-d/1500.)),1.);}`);
  const lnP = prog(`layout(location=0) in vec3 a;layout(location=1) in vec4 c;uniform mat4 vp;out vec4 vc;void main(){vc=c;gl_Position=vp*vec4(a,1.);}`,
    `in vec4 vc;out vec4 o;void main(){o=vc;}`);
  // ---- mesh and instances ----
  const me = M.mesh, NV = me.part.length;
  const birdVao = gl.createVertexArray(); gl.bindVertexArray(birdVao);
  const buf = (loc, data, size, type) => { const b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b); gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW); gl.enableVertexAttribArray(loc); gl.vertexAttribPointer(loc, size, type || gl.FLOAT, false, 0, 0); };
  buf(0, new Float32Array(me.p), 3); buf(1, new Float32Array(me.n), 3); buf(2, new Float32Array(me.c), 3);
  const ps = new Float32Array(2 * NV); for (let v = 0; v < NV; v++) { ps[2 * v] = me.part[v]; ps[2 * v + 1] = me.side[v]; } buf(3, ps, 2);
  const INST = new Float32Array(16 * B), instBuf = gl.createBuffer();
  gl.bindBuffer(gl.ARRAY_BUFFER, instBuf); gl.bufferData(gl.ARRAY_BUFFER, INST.byteLength, gl.DYNAMIC_DRAW);
  for (let k = 0; k < 4; k++) { gl.enableVertexAttribArray(4 + k); gl.vertexAttribPointer(4 + k, 4, gl.FLOAT, false, 64, 16 * k); gl.vertexAttribDivisor(4 + k, 1); }
  const grVao = gl.createVertexArray(); gl.bindVertexArray(grVao); buf(0, new Float32Array([-1, -1, 1, -1, 1, 1, -1, -1, 1, 1, -1, 1]), 2);
  const lnVao = gl.createVertexArray(); gl.bindVertexArray(lnVao);
  const lnPos = gl.createBuffer(), lnCol = gl.createBuffer();
  gl.bindBuffer(gl.ARRAY_BUFFER, lnPos); gl.enableVertexAttribArray(0); gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
  gl.bindBuffer(gl.ARRAY_BUFFER, lnCol); gl.enableVertexAttribArray(1); gl.vertexAttribPointer(1, 4, gl.FLOAT, false, 0, 0);
  gl.bindVertexArray(null);
  // ---- data access ----
  const val16 = (a, i, s) => a[i] === -32768 ? NaN : a[i] / s;
  function bird(k, b) { // stored frame k (integer)
    const i = k * B + b, j = 7 * i;
    return { x: POS[3 * i], y: POS[3 * i + 1], z: POS[3 * i + 2], h: HDG[i] / SC.heading, bank: I8[j] / SC.i8[0], pitch: I8[j + 1] / SC.i8[1],
      dih: I8[j + 2] / SC.i8[2], hdih: I8[j + 3] / SC.i8[3], sweep: I8[j + 4] / SC.i8[4], spread: I8[j + 5] / SC.i8[5], legs: I8[j + 6] / SC.i8[6],
      e: val16(E, i, SC.e), total: val16(TOT, i, SC.total) };
  }
  const wrap = a => a - 2 * Math.PI * Math.round(a / (2 * Math.PI));
  // Flock centre, heading and radius per stored frame, smoothed over about a second (follow camera).
  const CEN = new Float32Array(3 * F), HD = new Float32Array(F), RAD = new Float32Array(F);
  for (let k = 0; k < F; k++) {
    let x = 0, y = 0, z = 0, sx = 0, sy = 0;
    for (let b = 0; b < B; b++) { const i = k * B + b; x += POS[3 * i]; y += POS[3 * i + 1]; z += POS[3 * i + 2]; const h = HDG[i] / SC.heading; sx += Math.sin(h); sy += Math.cos(h); }
    x /= B; y /= B; z /= B; let r = 0;
    for (let b = 0; b < B; b++) { const i = k * B + b; r = Math.max(r, Math.hypot(POS[3 * i] - x, POS[3 * i + 1] - y, POS[3 * i + 2] - z)); }
    CEN[3 * k] = x; CEN[3 * k + 1] = y; CEN[3 * k + 2] = z; HD[k] = Math.atan2(sx, sy); RAD[k] = r;
  }
  const fpsStored = M.fps / M.every, sig = Math.max(1, fpsStored), half = Math.ceil(2 * sig);
  const SC3 = new Float32Array(3 * F), SHD = new Float32Array(F), SR = new Float32Array(F);
  for (let k = 0; k < F; k++) {
    let w = 0, x = 0, y = 0, z = 0, hs = 0, hc = 0, r = 0;
    for (let d = -half; d <= half; d++) { const j = Math.min(F - 1, Math.max(0, k + d)), g = Math.exp(-d * d / (2 * sig * sig)); w += g; x += g * CEN[3 * j]; y += g * CEN[3 * j + 1]; z += g * CEN[3 * j + 2]; hs += g * Math.sin(HD[j]); hc += g * Math.cos(HD[j]); r = Math.max(r, RAD[j]); }
    SC3[3 * k] = x / w; SC3[3 * k + 1] = y / w; SC3[3 * k + 2] = z / w; SHD[k] = Math.atan2(hs, hc); SR[k] = r;
  }
  // Colour ranges: the 2nd to 98th percentile of the values (a few extreme ones at hand-overs
  // would otherwise wash out the rest).
  function range(A, s) {
    const step = Math.max(1, Math.floor(A.length / 200000)), v = [];
    for (let i = 0; i < A.length; i += step) if (A[i] !== -32768) v.push(A[i] / s);
    if (!v.length) return [0, 1];
    v.sort((a, b) => a - b); return [v[Math.floor(0.02 * (v.length - 1))], v[Math.ceil(0.98 * (v.length - 1))]];
  }
  const [eMin, eMax] = range(E, SC.e), [tMin, tMax] = range(TOT, SC.total);
  // ---- state ----
  const S = { u: 0, playing: true, speed: 1, cam: "follow", colour: "plumage", trails: "off", wake: false, sel: -1,
    yaw: 0, elev: 0.35, zoom: 1, target: [CEN[0], CEN[1], CEN[2]], dist: 20, fovZoom: 1, frames: 0, lastMs: 0, drawMs: 0 };
  const timeAt = u => { const i = Math.min(F - 1, Math.floor(u)), j = Math.min(F - 1, i + 1); return T[i] + (T[j] - T[i]) * (u - i); };
  const uAt = t => { if (t <= T[0]) return 0; if (t >= T[F - 1]) return F - 1; let lo = 0, hi = F - 1; while (hi - lo > 1) { const m = (lo + hi) >> 1; if (T[m] <= t) lo = m; else hi = m; } return lo + (t - T[lo]) / (T[hi] - T[lo]); };
  const frameNumber = u => M.start_frame + Math.round(u * M.every);
  const stageAt = u => { const f = Math.round(u * M.every); const s = M.stages.find(s => f >= s.start && f < s.end); return s ? s.name : ""; };
  // Rank in its formation from the front, along the formation's mean heading, at frame k.
  function ranks(k) {
    const groups = new Map(), r = new Int32Array(B);
    for (let b = 0; b < B; b++) { const g = M.formation_of ? M.formation_of[b] : 0; if (!groups.has(g)) groups.set(g, []); groups.get(g).push(b); }
    for (const birds of groups.values()) {
      let sx = 0, sy = 0; for (const b of birds) { const h = HDG[k * B + b] / SC.heading; sx += Math.sin(h); sy += Math.cos(h); }
      const a = Math.atan2(sx, sy), fx = Math.sin(a), fy = Math.cos(a);
      const along = b => POS[3 * (k * B + b)] * fx + POS[3 * (k * B + b) + 1] * fy;
      birds.slice().sort((p, q) => along(q) - along(p)).forEach((b, i) => { r[b] = i; });
    }
    return r;
  }
  const PAL = [[.89, .1, .11], [.22, .49, .72], [.3, .69, .29], [.6, .31, .64], [1, .5, 0], [.65, .34, .16], [.97, .51, .75], [.1, .6, .6]];
  function ramp(x) { // blue → yellow (viridis-like)
    const st = [[.27, .0, .33], [.23, .32, .55], [.13, .57, .55], [.37, .79, .38], [.99, .91, .14]];
    x = Math.min(1, Math.max(0, x)) * 4; const i = Math.min(3, Math.floor(x)), f = x - i;
    return [0, 1, 2].map(c => st[i][c] + (st[i + 1][c] - st[i][c]) * f);
  }
  let rankCache = { k: -1, r: null };
  function colourOf(b, k, st) {
    const m = S.colour;
    if (m === "saving" || m === "total") {
      const v = m === "saving" ? st.e : st.total, lo = m === "saving" ? eMin : tMin, hi = m === "saving" ? eMax : tMax;
      return isNaN(v) ? [.55, .55, .55] : ramp((v - lo) / ((hi - lo) || 1));
    }
    if (m === "rank") { if (rankCache.k !== k) rankCache = { k, r: ranks(k) }; const r = rankCache.r[b]; return r === 0 ? [.9, .1, .1] : ramp(1 - r / Math.max(1, B - 1)); }
    if (m === "formation") return PAL[(M.formation_of ? M.formation_of[b] : 0) % PAL.length];
    return null;
  }
  // Interpolated state of every bird at u, into INST; returns the drawn positions.
  function fill(u) {
    const i = Math.min(F - 1, Math.floor(u)), j = Math.min(F - 1, i + 1), w = u - i, kn = w < 0.5 ? i : j;
    for (let b = 0; b < B; b++) {
      const a = bird(i, b), c = bird(j, b), o = 16 * b, L = (p, q) => p + (q - p) * w;
      INST[o] = L(a.x, c.x); INST[o + 1] = L(a.y, c.y); INST[o + 2] = L(a.z, c.z); INST[o + 3] = a.h + wrap(c.h - a.h) * w;
      INST[o + 4] = L(a.bank, c.bank); INST[o + 5] = L(a.pitch, c.pitch); INST[o + 6] = L(a.dih, c.dih); INST[o + 7] = L(a.hdih, c.hdih);
      INST[o + 8] = L(a.sweep, c.sweep); INST[o + 9] = L(a.spread, c.spread); INST[o + 10] = L(a.legs, c.legs); INST[o + 11] = b === S.sel ? 1 : 0;
      const col = colourOf(b, kn, kn === i ? a : c);
      if (col) { INST[o + 12] = col[0]; INST[o + 13] = col[1]; INST[o + 14] = col[2]; INST[o + 15] = 0.85; } else INST[o + 15] = 0;
    }
  }
  // ---- cameras ----
  function camera(asp) {
    const k = Math.min(F - 1, Math.round(S.u)), c = [SC3[3 * k], SC3[3 * k + 1], SC3[3 * k + 2]], r = SR[k] + 2;
    let eye, tgt, up = [0, 0, 1], fov = 0.8;
    if (S.cam === "ground") {
      eye = M.ground_eye.slice(); tgt = [CEN[3 * k], CEN[3 * k + 1], CEN[3 * k + 2]];
      const d = Math.hypot(...sub(tgt, eye)); fov = Math.min(1.05, Math.max(0.05, 2 * Math.atan(1.3 * r / d))) / S.fovZoom;
    } else if (S.cam === "top") {
      tgt = c; const d = S.zoom * r / Math.tan(0.4) * 1.1; eye = [c[0], c[1], c[2] + d]; up = [0, 1, 0];
    } else {
      let yaw, dist;
      if (S.cam === "follow") { tgt = c; yaw = SHD[k] + Math.PI + S.yaw; dist = S.zoom * (1.6 * r + 4); }
      else { tgt = S.target; yaw = S.yaw; dist = S.dist; }
      const ce = Math.cos(S.elev); eye = [tgt[0] + dist * ce * Math.sin(yaw), tgt[1] + dist * ce * Math.cos(yaw), tgt[2] + dist * Math.sin(S.elev)];
    }
    eye[2] = Math.max(eye[2], 0.3);
    const d = Math.hypot(...sub(tgt, eye)), near = Math.min(5, Math.max(0.02, d * 0.01));
    const v = look(eye, tgt, up), p = persp(fov, asp, near, 20000);
    return { eye, tgt, vp: mul(p, v) };
  }
  // ---- lines: trails and the chosen bird's trailing vortices ----
  function lines(u, eye) {
    const P = [], C = [];
    const seg = (a, b, c) => { P.push(a[0], a[1], a[2], b[0], b[1], b[2]); C.push(...c, ...c); };
    const k = Math.min(F - 1, Math.floor(u)), back = Math.max(2, Math.round(3 * fpsStored));
    if (S.trails !== "off") {
      const list = S.trails === "all" ? [...Array(Math.min(B, 3000)).keys()] : (S.sel >= 0 ? [S.sel] : []);
      const step = Math.max(1, Math.floor(back / 30));
      for (const b of list) for (let j = k; j > Math.max(0, k - back); j -= step) {
        const i0 = 3 * (j * B + b), i1 = 3 * (Math.max(0, j - step) * B + b), al = 0.8 * (1 - (k - j) / back);
        seg([POS[i0], POS[i0 + 1], POS[i0 + 2]], [POS[i1], POS[i1 + 1], POS[i1 + 2]], [.15, .15, .2, al]);
      }
    }
    if (S.wake) {
      const b = S.sel >= 0 ? S.sel : (M.leaders[0] || 0), half = M.vortex_span / 2, rc = Math.max(0.03, M.core_radius);
      for (const side of [1, -1]) {
        let prev = null;
        for (let j = k; j > Math.max(0, k - 2 * back); j--) {
          const s = bird(j, b), age = (T[k] - T[j]);
          const rx = Math.cos(s.h), ry = -Math.sin(s.h); // right of the heading
          // Helix round the core: turning inboard-down (right vortex counter-clockwise seen from behind).
          const th = side * 2 * Math.PI * age * 2;
          const ox = rc * Math.cos(th), oz = rc * Math.sin(th);
          const p = [s.x + rx * (side * half + ox), s.y + ry * (side * half + ox), s.z + oz];
          if (prev) seg(prev, p, side > 0 ? [.9, .35, .1, 0.9 - 0.4 * age / 6] : [.1, .45, .9, 0.9 - 0.4 * age / 6]);
          prev = p;
        }
      }
    }
    return [new Float32Array(P), new Float32Array(C)];
  }
  // ---- drawing ----
  let last = null;
  function render(opts) {
    opts = opts || {};
    const w = cv.clientWidth || 800, h = cv.clientHeight || 450, dpr = Math.min(2, window.devicePixelRatio || 1);
    if (cv.width !== Math.round(w * dpr) || cv.height !== Math.round(h * dpr)) { cv.width = Math.round(w * dpr); cv.height = Math.round(h * dpr); }
    gl.viewport(0, 0, cv.width, cv.height);
    const t = performance.now();
    fill(S.u);
    const cam = camera(cv.width / cv.height);
    gl.disable(gl.BLEND); gl.enable(gl.DEPTH_TEST); gl.clearColor(.8, .88, .95, 1); gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.depthMask(false); gl.useProgram(skyP.p); gl.uniformMatrix4fv(skyP.u.ivp, false, inv(cam.vp)); gl.uniform3fv(skyP.u.eye, cam.eye); gl.bindVertexArray(null); gl.drawArrays(gl.TRIANGLES, 0, 3); gl.depthMask(true);
    gl.useProgram(grP.p); gl.uniformMatrix4fv(grP.u.vp, false, cam.vp); gl.uniform3fv(grP.u.c, [cam.tgt[0], cam.tgt[1], 0]); gl.uniform3fv(grP.u.eye, cam.eye);
    gl.uniform3fv(grP.u.col, M.surface === "water" ? [.27, .45, .58] : [.45, .55, .35]); gl.bindVertexArray(grVao);
    // The ground writes no depth: nothing is ever below it, and the depth of its two huge
    // triangles, interpolated across thousands of wingspans, can land above a sitting bird's body
    // (the birds vanished into the field at some viewport sizes).
    gl.depthMask(false); gl.drawArrays(gl.TRIANGLES, 0, 6); gl.depthMask(true);
    if (!opts.noBirds) {
      gl.useProgram(birdP.p); gl.uniformMatrix4fv(birdP.u.vp, false, cam.vp);
      gl.uniform4f(birdP.u.geo, me.shoulder, me.arm, FOLD.arm, FOLD.hand); gl.uniform3fv(birdP.u.hip, me.hip);
      gl.bindVertexArray(birdVao); gl.bindBuffer(gl.ARRAY_BUFFER, instBuf); gl.bufferSubData(gl.ARRAY_BUFFER, 0, INST);
      gl.drawArraysInstanced(gl.TRIANGLES, 0, NV, B);
    }
    const [LP, LC] = lines(S.u, cam.eye);
    if (LP.length) {
      gl.enable(gl.BLEND); gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA); gl.useProgram(lnP.p); gl.uniformMatrix4fv(lnP.u.vp, false, cam.vp);
      gl.bindVertexArray(lnVao); gl.bindBuffer(gl.ARRAY_BUFFER, lnPos); gl.bufferData(gl.ARRAY_BUFFER, LP, gl.DYNAMIC_DRAW);
      gl.bindBuffer(gl.ARRAY_BUFFER, lnCol); gl.bufferData(gl.ARRAY_BUFFER, LC, gl.DYNAMIC_DRAW); gl.drawArrays(gl.LINES, 0, LP.length / 3);
    }
    gl.bindVertexArray(null);
    last = cam; S.frames++; S.drawMs = performance.now() - t;
    if (!opts.quiet) { drawTimeline(); info(); }
  }
  // ---- interface ----
  const sizeMB = v => (v / 1e6).toFixed(v < 1e7 ? 2 : 1) + " MB";
  const pageBytes = +($("fp-bytes") ? $("fp-bytes").textContent : 0);
  ui.innerHTML = `<canvas id="fp-tl"></canvas><div><button id="fp-play" title="play / pause (space)">❚❚</button>
<select id="fp-speed" title="speed (+/−)"><option>0.25</option><option>0.5</option><option selected>1</option><option>2</option><option>4</option></select>×
<select id="fp-cam" title="camera (1–4)"><option value="follow">follow</option><option value="orbit">orbit</option><option value="ground">ground</option><option value="top">top</option></select>
<button id="fp-frame" title="frame the flock (f)">frame flock</button>
<select id="fp-colour" title="colour (c)"><option value="plumage">plumage</option><option value="saving">saving (induced)</option><option value="total">saving (total)</option><option value="rank">rank</option><option value="formation">formation</option></select>
<select id="fp-trails" title="trails (t)"><option value="off">no trails</option><option value="sel">trail of the chosen bird</option><option value="all">trails of all</option></select>
<label title="trailing vortices of the chosen bird, or the leader (w)"><input type="checkbox" id="fp-wake"> wake</label>
<span id="fp-where"></span></div>`;
  const legend = document.createElement("div"); legend.id = "fp-legend"; document.getElementById("fp-root").appendChild(legend);
  const infoBox = document.createElement("div"); infoBox.id = "fp-info"; document.getElementById("fp-root").appendChild(infoBox);
  const tl = $("fp-tl"), tctx = tl.getContext("2d");
  const KIND = { leader_change: ["L", "#d62728", "leader change"], swap: ["S", "#1f77b4", "swap"], join: ["J", "#2ca02c", "join"], merge: ["M", "#9467bd", "merge"], split: ["X", "#ff7f0e", "split"] };
  function drawTimeline() {
    const w = tl.clientWidth, h = tl.clientHeight; if (tl.width !== w) tl.width = w; if (tl.height !== h) tl.height = h;
    const x = u => 6 + (w - 12) * (F > 1 ? u / (F - 1) : 0), xf = f => x(f / M.every);
    tctx.clearRect(0, 0, w, h);
    const sc = { initiation: "#f3d9a4", steady: "#bfdcb5", landing: "#c8c2e6" };
    for (const s of M.stages) { tctx.fillStyle = sc[s.name] || "#ddd"; tctx.fillRect(xf(s.start), 2, xf(s.end) - xf(s.start), 16); tctx.fillStyle = "#333"; tctx.font = "11px sans-serif"; tctx.fillText(s.name, xf(s.start) + 3, 14); }
    tctx.fillStyle = "#999"; tctx.fillRect(6, 28, w - 12, 2);
    for (const e of M.events) { const k = KIND[e.kind] || ["?", "#555", e.kind], ex = x(uAt(e.t)); tctx.fillStyle = k[1]; tctx.fillRect(ex - 1, 20, 3, 18); tctx.font = "bold 10px sans-serif"; tctx.fillText(k[0], ex + 3, 42); }
    tctx.fillStyle = "#000"; tctx.fillRect(x(S.u) - 1, 0, 2, h);
    $("fp-where").textContent = `frame ${frameNumber(S.u)} · t ${timeAt(S.u).toFixed(2)} s · ${stageAt(S.u)} · ${B} birds`;
  }
  function legendHtml() {
    const m = S.colour, bar = (lo, hi, what) => `<div>${what}</div><div id="fp-bar" style="background:linear-gradient(90deg,${[0, .25, .5, .75, 1].map(v => "rgb(" + ramp(v).map(c => Math.round(255 * c)).join(",") + ")").join(",")})"></div><div>${lo} <span style="float:right">${hi}</span></div>`;
    const pc = v => (100 * v).toFixed(1) + " %";
    let s = `<b>${M.title.replace(/[<&]/g, "")}</b><br>`;
    if (m === "saving") s += bar(pc(eMin), pc(eMax), "saving of induced power, 2nd to 98th percentile (model estimate: " + M.savings_model.replace(/[<&]/g, "") + "); grey: none defined");
    else if (m === "total") s += bar(pc(tMin), pc(tMax), "saving of total power (model estimate, Pennycuick's power curve); grey: none defined");
    else if (m === "rank") s += `<span style="color:#e51a1a">■</span> leader (rank 0) ` + bar("rank 1", "rank " + (B - 1), "");
    else if (m === "formation") s += (M.leaders.length ? M.leaders : [0]).map((_, i) => `<span style="color:rgb(${PAL[i % PAL.length].map(c => Math.round(255 * c))})">■</span> formation ${i + 1}`).join("<br>");
    else s += M.species + " plumage; events on the timeline: " + Object.values(KIND).map(k => `<span style="color:${k[1]}">${k[0]}</span> ${k[2]}`).join(", ");
    s += `<div id="fp-sz">${sizeMB(M.data_bytes)} of frames embedded (float32 positions, int16/int8 angles and savings, base64)${pageBytes ? ", page " + sizeMB(pageBytes) : ""}; loaded in ${Math.round(S.loadMs)} ms</div>`;
    legend.innerHTML = s;
  }
  function info() {
    if (S.sel < 0) { infoBox.style.display = "none"; return; }
    const k = Math.min(F - 1, Math.round(S.u)), s = bird(k, S.sel), k0 = Math.max(0, k - 1), k1 = Math.min(F - 1, k + 1), a = bird(k0, S.sel), c = bird(k1, S.sel);
    const v = k1 > k0 ? Math.hypot(c.x - a.x, c.y - a.y, c.z - a.z) / (T[k1] - T[k0]) : 0, deg = r => (r * 180 / Math.PI).toFixed(1) + "°", pc = x => isNaN(x) ? "–" : (100 * x).toFixed(1) + " %";
    if (rankCache.k !== k) rankCache = { k, r: ranks(k) };
    infoBox.style.display = "block";
    infoBox.textContent = `bird ${S.sel}${M.formation_of ? " · formation " + (M.formation_of[S.sel] + 1) : ""} · rank ${rankCache.r[S.sel]}
x ${s.x.toFixed(2)}  y ${s.y.toFixed(2)}  z ${s.z.toFixed(2)} wingspans
height ${(s.z * M.wingspan_m).toFixed(1)} m · speed ${(v * M.wingspan_m).toFixed(1)} m/s
heading ${deg(s.h)} · bank ${deg(s.bank)} · pitch ${deg(s.pitch)}
saving ${pc(s.e)} of induced power, ${pc(s.total)} of total
(model estimates)`;
  }
  // ---- input ----
  const set = (id, v) => { $(id).value = v; };
  function setCam(c) { if (c === "orbit" && S.cam !== "orbit") { const k = Math.min(F - 1, Math.round(S.u)); S.target = [SC3[3 * k], SC3[3 * k + 1], SC3[3 * k + 2]]; S.dist = 1.6 * SR[k] + 4; S.yaw = SHD[k] + Math.PI; } if (c === "follow") S.yaw = 0; S.cam = c; S.zoom = 1; set("fp-cam", c); }
  function frameFlock() {
    const k = Math.min(F - 1, Math.round(S.u)); S.cam = "orbit"; set("fp-cam", "orbit"); S.target = [CEN[3 * k], CEN[3 * k + 1], CEN[3 * k + 2]];
    S.dist = (RAD[k] + 1) / Math.tan(0.4) * 1.1; S.elev = Math.max(S.elev, 0.3);
  }
  const setColour = m => { S.colour = m; set("fp-colour", m); rankCache.k = -1; legendHtml(); };
  const setPlay = p => { S.playing = p; $("fp-play").textContent = p ? "❚❚" : "▶"; };
  $("fp-play").onclick = () => setPlay(!S.playing);
  $("fp-speed").onchange = e => { S.speed = +e.target.value; };
  $("fp-cam").onchange = e => setCam(e.target.value);
  $("fp-frame").onclick = frameFlock;
  $("fp-colour").onchange = e => setColour(e.target.value);
  $("fp-trails").onchange = e => { S.trails = e.target.value; };
  $("fp-wake").onchange = e => { S.wake = e.target.checked; };
  const seekU = u => { S.u = Math.min(F - 1, Math.max(0, u)); };
  let scrub = false;
  const tlU = ev => { const r = tl.getBoundingClientRect(); return (ev.clientX - r.left - 6) / (r.width - 12) * (F - 1); };
  tl.addEventListener("pointerdown", ev => { scrub = true; tl.setPointerCapture(ev.pointerId); seekU(tlU(ev)); });
  tl.addEventListener("pointermove", ev => { if (scrub) seekU(tlU(ev)); });
  tl.addEventListener("pointerup", () => { scrub = false; });
  const ptrs = new Map(); let moved = 0, pinch = 0;
  cv.addEventListener("pointerdown", ev => { cv.setPointerCapture(ev.pointerId); ptrs.set(ev.pointerId, [ev.clientX, ev.clientY, ev.button, ev.shiftKey]); moved = 0; });
  cv.addEventListener("pointermove", ev => {
    const p = ptrs.get(ev.pointerId); if (!p) return;
    const dx = ev.clientX - p[0], dy = ev.clientY - p[1]; moved += Math.abs(dx) + Math.abs(dy); p[0] = ev.clientX; p[1] = ev.clientY;
    if (ptrs.size === 2) { const [a, b] = [...ptrs.values()], d = Math.hypot(a[0] - b[0], a[1] - b[1]); if (pinch) zoomBy(pinch / d); pinch = d; return; }
    if ((p[2] === 2 || p[3]) && S.cam === "orbit" && last) { // pan
      const f = S.dist * 0.0015, r = norm(cross(sub(last.tgt, last.eye), [0, 0, 1]));
      S.target = [S.target[0] - r[0] * dx * f, S.target[1] - r[1] * dx * f, S.target[2] + dy * f];
    } else if (S.cam !== "ground") { S.yaw -= dx * 0.006; S.elev = Math.min(1.5, Math.max(-0.05, S.elev + dy * 0.006)); }
  });
  cv.addEventListener("contextmenu", ev => ev.preventDefault());
  cv.addEventListener("pointerup", ev => { ptrs.delete(ev.pointerId); pinch = 0; if (moved < 4) pick(ev); });
  cv.addEventListener("pointercancel", ev => { ptrs.delete(ev.pointerId); pinch = 0; });
  function zoomBy(f) { if (S.cam === "orbit") S.dist *= f; else if (S.cam === "ground") S.fovZoom /= f; else S.zoom *= f; }
  cv.addEventListener("wheel", ev => { ev.preventDefault(); zoomBy(Math.exp(ev.deltaY * 0.001)); }, { passive: false });
  // Screen position (CSS pixels) of a world point, or null behind the camera.
  function project(p) {
    if (!last) return null; const m = last.vp, x = m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12], y = m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13], w = m[3] * p[0] + m[7] * p[1] + m[11] * p[2] + m[15];
    if (w <= 0) return null; return [(x / w * 0.5 + 0.5) * cv.clientWidth, (0.5 - y / w * 0.5) * cv.clientHeight];
  }
  function pick(ev) {
    const r = cv.getBoundingClientRect(), mx = ev.clientX - r.left, my = ev.clientY - r.top; let best = -1, bd = 18;
    for (let b = 0; b < B; b++) { const q = project([INST[16 * b], INST[16 * b + 1], INST[16 * b + 2]]); if (q) { const d = Math.hypot(q[0] - mx, q[1] - my); if (d < bd) { bd = d; best = b; } } }
    S.sel = best; if (!S.playing) render();
  }
  window.addEventListener("keydown", ev => {
    if (ev.target && ev.target.tagName === "SELECT") return;
    const k = ev.key, step = ev.shiftKey ? fpsStored : 1;
    if (k === " ") { setPlay(!S.playing); ev.preventDefault(); } else if (k === "ArrowRight") seekU(Math.round(S.u) + step); else if (k === "ArrowLeft") seekU(Math.round(S.u) - step);
    else if (k === "Home") seekU(0); else if (k === "End") seekU(F - 1); else if (k === "f") frameFlock();
    else if ("1234".includes(k)) setCam(["follow", "orbit", "ground", "top"][+k - 1]);
    else if (k === "c") { const o = ["plumage", "saving", "total", "rank", "formation"]; setColour(o[(o.indexOf(S.colour) + 1) % o.length]); }
    else if (k === "t") { S.trails = { off: "sel", sel: "all", all: "off" }[S.trails]; set("fp-trails", S.trails); }
    else if (k === "w") { S.wake = !S.wake; $("fp-wake").checked = S.wake; }
    else if (k === "+" || k === "-") { const v = [0.25, 0.5, 1, 2, 4], i = Math.max(0, Math.min(4, v.indexOf(S.speed) + (k === "+" ? 1 : -1))); S.speed = v[i]; set("fp-speed", String(v[i])); }
    else return;
    if (!S.playing) render();
  });
  function tick(dtMs) { if (S.playing) { const t = timeAt(S.u) + dtMs / 1000 * S.speed; S.u = t >= T[F - 1] ? 0 : uAt(t); } }
  function loop(now) { const dt = S.lastMs ? Math.min(100, now - S.lastMs) : 0; S.lastMs = now; tick(dt); render(); requestAnimationFrame(loop); }
  // ---- start: #frame=N&camera=…&colour=…&select=B&trails=…&wake=1&play=0 ----
  const q = new URLSearchParams(location.hash.slice(1));
  if (q.has("frame")) seekU((+q.get("frame") - M.start_frame) / M.every);
  if (q.has("camera")) setCam(q.get("camera"));
  if (q.has("colour")) setColour(q.get("colour"));
  if (q.has("select")) S.sel = +q.get("select");
  if (q.has("trails")) { S.trails = q.get("trails"); set("fp-trails", S.trails); }
  if (q.has("wake")) { S.wake = q.get("wake") === "1"; $("fp-wake").checked = S.wake; }
  setPlay(q.get("play") !== "0");
  S.loadMs = performance.now() - t0;
  legendHtml(); render();
  requestAnimationFrame(loop);
  // The page's state, for tests and for scripting in the browser console.
  window.formationPlayer = {
    ready: true, birds: B, frames: F, every: M.every, startFrame: M.start_frame, loadMs: S.loadMs, state: S,
    get frame() { return frameNumber(S.u); },
    seek(frameNo) { seekU((frameNo - M.start_frame) / M.every); render(); return frameNumber(S.u); },
    play() { setPlay(true); }, pause() { setPlay(false); }, tick(ms) { tick(ms); render(); },
    setCamera: setCam, setColour, select(b) { S.sel = b; render(); }, frameFlock() { frameFlock(); render(); },
    drawn() { const o = []; for (let b = 0; b < B; b++) o.push([INST[16 * b], INST[16 * b + 1], INST[16 * b + 2]]); return o; },
    project,
    pixels(noBirds) { render({ noBirds, quiet: true }); const p = new Uint8Array(cv.width * cv.height * 4); gl.readPixels(0, 0, cv.width, cv.height, gl.RGBA, gl.UNSIGNED_BYTE, p); return p; },
    // Birds whose drawn place on screen differs from the picture without birds, of those in view.
    // Birds in view, and how many of them change the pixels at their projected place; `big`
    // counts those whose wingspan spans at least `minPx` pixels across the view (`bigSeen` of
    // them drawn; `missed`: the first ten of the others): a far bird under a pixel may vanish
    // (no antialiasing), a bird that large must not.
    birdsSeen(minPx = 3) {
      const a = this.pixels(false), n = this.pixels(true), W = cv.width, H = cv.height, s = W / cv.clientWidth; let seen = 0, inView = 0, big = 0, bigSeen = 0; const missed = [];
      let right = cross(norm(sub(last.tgt, last.eye)), [0, 0, 1]); right = Math.hypot(...right) < 1e-6 ? [1, 0, 0] : norm(right);
      for (let b = 0; b < B; b++) {
        const p = [INST[16 * b], INST[16 * b + 1], INST[16 * b + 2]], q = project(p); if (!q) continue;
        const px = Math.round(q[0] * s), py = H - 1 - Math.round(q[1] * s); if (px < 3 || py < 3 || px >= W - 3 || py >= H - 3) continue;
        const r = project([p[0] + right[0], p[1] + right[1], p[2] + right[2]]), large = !!r && Math.hypot(r[0] - q[0], r[1] - q[1]) * s >= minPx;
        inView++; if (large) big++; let hit = false;
        for (let dy = -3; dy <= 3 && !hit; dy++) for (let dx = -3; dx <= 3 && !hit; dx++) { const i = 4 * ((py + dy) * W + px + dx); if (Math.abs(a[i] - n[i]) + Math.abs(a[i + 1] - n[i + 1]) + Math.abs(a[i + 2] - n[i + 2]) > 12) hit = true; }
        if (hit) { seen++; if (large) bigSeen++; } else if (large && missed.length < 10) missed.push({ bird: b, px, py, wide: Math.hypot(r[0] - q[0], r[1] - q[1]) * s, at: p });
      }
      render(); return { seen, inView, big, bigSeen, missed };
    },
    // Milliseconds a frame takes to draw (JS interpolation + WebGL, waited for), over n frames.
    benchmark(n) { const p = new Uint8Array(4), t = performance.now(); for (let i = 0; i < n; i++) { tick(1000 / 30); render({ quiet: true }); gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, p); } return (performance.now() - t) / n; },
  };
})();
