// Loads a .glb written by `formation` with three.js (GLTFLoader, in Node), plays its first clip
// with an AnimationMixer and checks what a web viewer would show: the draw calls (meshes), the
// clip's length, every bird's root at 10 frames where the CSV of the same animation puts it
// (within 1 mm), the first bird's wing turning, and each skinned mesh deformed around its bird.
// Usage: node .ci/three_check.mjs flock.glb flock.csv
import { readFileSync } from "node:fs";
import * as THREE from "./node/node_modules/three/build/three.module.js";
import { GLTFLoader } from "./node/node_modules/three/examples/jsm/loaders/GLTFLoader.js";

const [glbPath, csvPath] = process.argv.slice(2);
const bytes = readFileSync(glbPath);
const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
const gltf = await new Promise((resolve, reject) => new GLTFLoader().parse(buffer, "", resolve, reject));
const failed = [];
const extras = gltf.scene.userData ?? {};
const fps = extras.fps ?? 30;
const ws = extras.wingspan_m ?? 1.5;
const start = extras.frame_start ?? 0;
const birds = [];
gltf.scene.traverse((o) => { if (/^bird_\d+$/.test(o.name)) birds.push(o); });
birds.sort((a, b) => a.name.localeCompare(b.name));
let meshes = 0, skinned = 0;
gltf.scene.traverse((o) => { if (o.isMesh) { meshes += 1; if (o.isSkinnedMesh) skinned += 1; } });
const clip = gltf.animations[0];
console.log(`LOADED ${birds.length} birds, ${meshes} meshes (${skinned} skinned): ${meshes} draw calls; clips ${gltf.animations.map((c) => c.name).join(", ")}; first clip ${clip.duration.toFixed(3)} s`);
if (birds.length === 0) failed.push("no bird nodes");
const mixer = new THREE.AnimationMixer(gltf.scene);
// Played once and held at its end (a looping action wraps to its start at the last frame).
const action = mixer.clipAction(clip);
action.setLoop(THREE.LoopOnce);
action.clampWhenFinished = true;
action.play();

// The CSV: frame, bird, x, y, z (wingspans, z up) → three.js's Y-up metres: (x, z, -y) × ws.
const lines = readFileSync(csvPath, "utf8").trim().split("\n");
const head = lines[0].split(",");
const col = (n) => head.indexOf(n);
const [cf, cb, cx, cy, cz] = ["frame", "bird", "x", "y", "z"].map(col);
const rows = new Map();
let lastFrame = start;
for (const line of lines.slice(1)) {
  const v = line.split(",");
  const f = Number(v[cf]);
  lastFrame = Math.max(lastFrame, f);
  rows.set(`${f}/${Number(v[cb])}`, [Number(v[cx]) * ws, Number(v[cz]) * ws, -Number(v[cy]) * ws]);
}
const picks = [...Array(10).keys()].map((i) => start + Math.round((i * (lastFrame - start)) / 9));
let worst = 0, at = "";
const p = new THREE.Vector3();
const seek = (t) => {
  action.reset();
  action.time = t;
  mixer.update(0);
  gltf.scene.updateMatrixWorld(true);
};
for (const f of picks) {
  seek(f / fps);
  birds.forEach((node, b) => {
    const want = rows.get(`${f}/${b}`);
    node.getWorldPosition(p);
    const err = Math.max(Math.abs(p.x - want[0]), Math.abs(p.y - want[1]), Math.abs(p.z - want[2]));
    if (err > worst) { worst = err; at = `frame ${f} ${node.name}`; }
  });
}
console.log(`POSITIONS 10 frames ${picks[0]}..${picks[9]}: worst ${worst.toFixed(6)} m (${at})`);
if (worst > 0.001) failed.push(`positions off the CSV by ${worst.toFixed(4)} m at ${at}`);

// The first bird's wing over a second of the middle of the clip, and its skinned mesh around it.
let wing = null;
birds[0].traverse((o) => { if (wing === null && /upper_arm\.?L$/.test(o.name)) wing = o; });
const angles = new Set();
const mid = Math.round((start + lastFrame) / 2);
for (let f = mid; f <= mid + fps; f++) {
  seek(f / fps);
  angles.add(wing.quaternion.toArray().map((v) => v.toFixed(4)).join(","));
}
console.log(`WING ${wing.name}: ${angles.size} poses over a second`);
if (angles.size < 10) failed.push("the first bird's wing does not turn");
let farthest = 0;
gltf.scene.traverse((o) => {
  if (!o.isSkinnedMesh) return;
  o.skeleton.update();
  const v = new THREE.Vector3();
  const n = Math.min(o.geometry.attributes.position.count, 400);
  const birdOf = o.skeleton.bones.find((bone) => /^bird_\d+$/.test(bone.name)) ?? o.skeleton.bones[0].parent;
  birdOf.getWorldPosition(p);
  for (let i = 0; i < n; i++) {
    o.getVertexPosition(i, v);
    v.applyMatrix4(o.matrixWorld);
    farthest = Math.max(farthest, v.distanceTo(p));
  }
});
console.log(`SKINNED the first vertices of every mesh at most ${farthest.toFixed(3)} m from their bird`);
if (!(farthest < 1.2 * ws)) failed.push(`skinned vertices ${farthest.toFixed(3)} m from their bird`);
if (failed.length) { console.log(`FAILED ${failed.join("; ")}`); process.exit(1); }
console.log("OK");
