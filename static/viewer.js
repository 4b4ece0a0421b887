// Motion viewer of the studio: plays the GLB that motion_core.export_gltf writes.
//
// viewer.html?glb=URL loads the file with GLTFLoader, drives its animation with an
// AnimationMixer (scrubbed by setting the mixer's time), and shows the file's skinned body
// when it has one, or the skeleton as capsules between the animated joint nodes (left side
// blue, right side red; a checkbox switches between the two). The timeline's segments
// and key frames come from the file itself (scene extras -> gltf.scene.userData). A motion on
// stairs brings the steps under its feet (extras.steps, motion_core.body.terrain.steps): each
// is drawn as a box standing on the floor.
//
// window.viewer exposes the player's state (time, playing, frames, ...) and a few controls
// for scripts and browser tests; it is not needed to use the page.
import * as THREE from "three";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";
import { OrbitControls } from "three/addons/controls/OrbitControls.js";

const $ = (id) => document.getElementById(id);
const params = new URLSearchParams(location.search);
const SEGMENT_COLOURS = ["#4e79a7", "#f28e2b", "#59a14f", "#e15759", "#76b7b2", "#edc948", "#b07aa1", "#ff9da7", "#9c755f", "#bab0ac"];
const SIDE_COLOURS = { left: 0x3b6fd8, right: 0xd84a3b, centre: 0x8a8f98 };
const GHOST_COLOUR = 0xc2185b;

const state = (window.viewer = {
  url: params.get("glb"),
  ready: false,
  error: null,
  fps: 20,
  frames: 0,
  duration: 0,
  time: 0,
  frame: 0,
  playing: false,
  speed: 1,
  loop: true,
  segments: [],
  keyframes: [],
  method: null,
  view: "follow", // camera: follow | front | side | top
  ghostFrames: [], // the key frames drawn as ghosts (thinned so that they stay readable)
  path: [], // the root's [x, z] per frame, drawn on the floor
  steps: [], // boxes under the feet of a motion on stairs: {center: [x, z], width, depth, yaw, top}
  renderedFrames: 0,
  hasBody: false, // the file carries a skinned body mesh
  showing: "bones", // what is drawn: "body" or "bones"
  recording: false, // a video is being recorded (the play clock stands still meanwhile)
  recordedFrames: 0,
  plays: 0, // complete play-throughs of this motion (a user study records whether both were watched)
  requestedAt: null, // Date.now() when this motion was asked for
  fetchedAt: null, // ... when its file was loaded and parsed
  loadedAt: null, // ... when its first frame was drawn
});

function showMessage(text, isError = false) {
  const el = $("message");
  el.textContent = text;
  el.classList.toggle("error", isError);
  el.hidden = !text;
}

// ---------------------------------------------------------------- scene
const stage = $("stage");
let renderer;
try {
  renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
} catch (err) {
  state.error = `WebGL is not available in this browser (${err.message})`;
  showMessage(state.error, true);
  throw err;
}
renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
renderer.shadowMap.enabled = true;
renderer.shadowMap.type = THREE.PCFShadowMap;
stage.appendChild(renderer.domElement);

const scene = new THREE.Scene();
scene.background = new THREE.Color(0xf4f1ea);
scene.fog = new THREE.Fog(0xf4f1ea, 12, 30);
const camera = new THREE.PerspectiveCamera(45, 1, 0.05, 100);
camera.position.set(2.6, 1.7, 3.6);
const controls = new OrbitControls(camera, renderer.domElement);
controls.target.set(0, 0.9, 0);
controls.enableDamping = true;

scene.add(new THREE.HemisphereLight(0xffffff, 0x8d7f6a, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 2.2);
sun.position.set(3, 6, 2);
sun.castShadow = true;
sun.shadow.mapSize.set(1024, 1024);
Object.assign(sun.shadow.camera, { left: -3, right: 3, top: 3, bottom: -3, near: 0.5, far: 20 });
scene.add(sun, sun.target);

const ground = new THREE.Mesh(
  new THREE.PlaneGeometry(60, 60),
  new THREE.MeshStandardMaterial({ color: 0xe6e0d4, roughness: 1 }),
);
ground.rotation.x = -Math.PI / 2;
ground.receiveShadow = true;
scene.add(ground);
const grid = new THREE.GridHelper(60, 60, 0x8f8472, 0xb3a993);
grid.position.y = 0.001;
scene.add(grid);

// ---------------------------------------------------------------- steps (stairs, a platform)
// A motion whose feet stand at other heights than the floor's brings the boxes under them
// (extras.steps): each stands on the floor, ``top`` high, its depth along the heading ``yaw``.
const stepMaterial = new THREE.MeshStandardMaterial({ color: 0xcfc6b4, roughness: 0.95 });
const stepEdgeMaterial = new THREE.LineBasicMaterial({ color: 0x6f6656 });
let stepGroup = null;

function buildSteps() {
  if (stepGroup) {
    stepGroup.traverse((o) => o.geometry && o.geometry.dispose());
    stepGroup.removeFromParent();
    stepGroup = null;
  }
  if (!state.steps.length) return;
  stepGroup = new THREE.Group();
  stepGroup.name = "steps";
  for (const s of state.steps) {
    const geo = new THREE.BoxGeometry(s.width, s.top, s.depth);
    const box = new THREE.Mesh(geo, stepMaterial);
    box.position.set(s.center[0], s.top / 2, s.center[1]);
    box.rotation.y = s.yaw;
    box.castShadow = true;
    box.receiveShadow = true;
    box.add(new THREE.LineSegments(new THREE.EdgesGeometry(geo), stepEdgeMaterial));
    stepGroup.add(box);
  }
  scene.add(stepGroup);
}

function groundUnder(x, z) {
  // the top of the highest step whose footprint holds (x, z); the floor (0) elsewhere
  let top = 0;
  for (const s of state.steps) {
    const dx = x - s.center[0];
    const dz = z - s.center[1];
    const along = dx * Math.sin(s.yaw) + dz * Math.cos(s.yaw);
    const across = dx * Math.cos(s.yaw) - dz * Math.sin(s.yaw);
    if (Math.abs(along) <= s.depth / 2 && Math.abs(across) <= s.width / 2) top = Math.max(top, s.top);
  }
  return top;
}

function resize() {
  // the controls wrap onto more rows on a narrow screen: the stage ends where they begin
  const bar = $("controls");
  stage.style.bottom = bar.hidden ? "0px" : `${bar.offsetHeight}px`;
  const w = stage.clientWidth || window.innerWidth;
  const h = stage.clientHeight || window.innerHeight;
  renderer.setSize(w, h);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
}
window.addEventListener("resize", resize);
resize();

// ---------------------------------------------------------------- skeleton drawing
const UP = new THREE.Vector3(0, 1, 0);
const unitCyl = new THREE.CylinderGeometry(1, 1, 1, 12);
const ball = new THREE.SphereGeometry(1, 14, 10);
const tmpA = new THREE.Vector3();
const tmpB = new THREE.Vector3();

function side(name) {
  // HumanML3D's names (left_knee) and the humanoid rig's (LeftLeg) alike
  const n = name.toLowerCase();
  if (n.startsWith("left")) return "left";
  if (n.startsWith("right")) return "right";
  return "centre";
}

class Figure {
  // Capsules between joints, placed from the joints' world positions.
  constructor(joints, ghost = false) {
    this.joints = joints;
    this.group = new THREE.Group();
    // ghosts (key-frame poses) are translucent and in the key-frame colour of the scrubber
    const mat = (c) =>
      ghost
        ? new THREE.MeshStandardMaterial({
            color: GHOST_COLOUR,
            roughness: 0.8,
            transparent: true,
            opacity: 0.5,
            depthWrite: false,
          })
        : new THREE.MeshStandardMaterial({ color: c, roughness: 0.6 });
    const opacity = ghost ? 0.5 : 1;
    this.bones = [];
    for (const j of joints) {
      if (!(j.parent && joints.includes(j.parent))) continue;
      const m = new THREE.Mesh(unitCyl, mat(SIDE_COLOURS[side(j.name)]));
      m.castShadow = opacity === 1;
      this.bones.push({ mesh: m, a: j.parent, b: j });
      this.group.add(m);
    }
    this.balls = joints.map((j) => {
      const head = j.name.toLowerCase() === "head";
      const m = new THREE.Mesh(ball, mat(head ? 0xe0b089 : 0x44474d));
      const r = head ? 0.09 : 0.028;
      m.scale.setScalar(r);
      m.castShadow = opacity === 1;
      this.group.add(m);
      return m;
    });
  }

  dispose() {
    this.group.traverse((o) => o.material && o.material.dispose());
    this.group.removeFromParent();
  }

  update() {
    for (const { mesh, a, b } of this.bones) {
      a.getWorldPosition(tmpA);
      b.getWorldPosition(tmpB);
      const len = tmpA.distanceTo(tmpB);
      mesh.position.copy(tmpA).add(tmpB).multiplyScalar(0.5);
      mesh.quaternion.setFromUnitVectors(UP, tmpB.sub(tmpA).normalize());
      mesh.scale.set(0.022, len, 0.022);
    }
    this.joints.forEach((j, i) => j.getWorldPosition(this.balls[i].position));
  }
}

// ---------------------------------------------------------------- player
let mixer = null;
let action = null; // the clip's one action; the viewer's own clock drives it (poseAt)
let figure = null;
let ghosts = null;
let rootJoint = null;
let joints = []; // the animated joint nodes, in the file's joint_names order
let bodyMeshes = [];

function showBody() {
  // the body by default when the file has one; the checkbox switches to the bones
  const box = $("body");
  box.disabled = !state.hasBody;
  $("body-label").title = state.hasBody ? "the skinned body, or the bones" : "this file has no body mesh";
  const on = state.hasBody && box.checked;
  state.showing = on ? "body" : "bones";
  for (const m of bodyMeshes) m.visible = on;
  if (figure) figure.group.visible = !on;
  dirty = true;
}
const lastRoot = new THREE.Vector3();
let lastGround = 0; // the follow camera's ground height (a step's top on stairs, else 0)
let dirty = true; // something changed since the last draw
let timeShown = true; // the figure, path and clock show state.time
// while the embedding page's request runs: {playing: whether to play on if it brings nothing}
let busy = null;

function poseAt(t) {
  // Pose the body at t seconds of the clip. The viewer keeps its own clock and does its own
  // looping, so the action plays once and holds its last key at the end: three.js's default,
  // a repeating action, wraps t = duration to 0, and a motion played to its end (or scrubbed
  // to its last frame) showed its first pose. A clamped action pauses at its end; reset()
  // re-arms it before each pose.
  action.reset();
  mixer.setTime(t);
}

function setTime(t) {
  moveTime(t);
  showTime();
}

// Playback moves the clock every animation frame but shows it only on frames that are drawn
// (MAX_FPS): posing the figure, repainting the path's colours and the page's clock and strip
// at the display's rate cost a software-GL browser more than drawing the scene.
function moveTime(t) {
  state.time = Math.min(Math.max(t, 0), state.duration);
  state.frame = Math.min(Math.round(state.time * state.fps), state.frames - 1);
  timeShown = false;
}

function showTime() {
  timeShown = true;
  if (mixer) poseAt(state.time);
  $("scrub").value = String(state.frame);
  paintPath();
  $("clock").textContent = `${state.time.toFixed(2)} / ${state.duration.toFixed(2)} s`;
  const seg = state.segments.findIndex((s) => state.frame >= s.start && state.frame < s.end);
  const last = state.segments.length - 1;
  const idx = seg >= 0 ? seg : state.frame >= state.frames - 1 ? last : -1;
  $("segment-text").textContent =
    idx >= 0 && state.segments.length ? `${idx + 1}/${state.segments.length} · ${state.segments[idx].text}` : "";
}

function setPlaying(on) {
  state.playing = on;
  const b = $("play");
  b.innerHTML = on ? "&#10074;&#10074;" : "&#9654;";
  b.setAttribute("aria-label", on ? "pause" : "play");
}

function buildTrack() {
  const bands = $("bands");
  const ticks = $("ticks");
  bands.replaceChildren();
  ticks.replaceChildren();
  const n = Math.max(state.frames, 1);
  state.segments.forEach((s, i) => {
    const d = document.createElement("div");
    d.className = "band";
    d.style.left = `${(100 * s.start) / n}%`;
    d.style.width = `${(100 * (s.end - s.start)) / n}%`;
    d.style.background = SEGMENT_COLOURS[i % SEGMENT_COLOURS.length];
    d.title = `${i + 1}: ${s.text}`;
    bands.appendChild(d);
  });
  for (const k of state.keyframes) {
    const t = document.createElement("div");
    t.className = "tick";
    t.style.left = `${(100 * k) / n}%`;
    t.title = `key frame ${k}`;
    ticks.appendChild(t);
  }
  const ghostBox = $("ghosts");
  ghostBox.disabled = state.keyframes.length === 0;
  $("ghost-label").title = state.keyframes.length
    ? "show the key frames as ghost poses"
    : "this motion has no key frames";
}

function thinKeyframes(keys, fps, duration) {
  // At most 8 ghosts, at least ~1 s apart (and a sixth of the motion on long ones): a method
  // may pick a key frame every few tenths of a second, and 25 overlapping ghosts read as one
  // blob. (This file names no method: the user study serves it to participants.)
  const gap = Math.max(fps, (duration * fps) / 6);
  const out = [];
  for (const k of [...keys].sort((a, b) => a - b)) {
    if (!out.length || k - out[out.length - 1] >= gap) out.push(k);
    if (out.length === 8) break;
  }
  return out;
}

function buildGhosts(joints) {
  // One translucent figure per (thinned) key frame, posed by the mixer at that frame.
  const group = new THREE.Group();
  const keep = state.time;
  state.ghostFrames = thinKeyframes(state.keyframes, state.fps, state.duration);
  for (const k of state.ghostFrames) {
    poseAt(k / state.fps);
    const f = new Figure(joints, true);
    f.update();
    group.add(f.group);
  }
  poseAt(keep);
  group.visible = false;
  scene.add(group);
  return group;
}

let motionScene = null;

// ---------------------------------------------------------------- root path on the floor
// The whole path is drawn faintly; the stretch just walked is dark and fades behind the body,
// so "walks in a circle clockwise" or "walks back" can be judged from any view.
let pathLine = null;
const PATH_FADE_FRAMES = 60;
const BG = new THREE.Color(0xe6e0d4);
const INK = new THREE.Color(0x2a5599);

function buildPath() {
  if (pathLine) {
    pathLine.geometry.dispose();
    pathLine.material.dispose();
    pathLine.removeFromParent();
  }
  const keep = state.time;
  state.path = [];
  for (let f = 0; f < state.frames; f++) {
    poseAt(f / state.fps);
    rootJoint.getWorldPosition(tmpA);
    state.path.push([tmpA.x, tmpA.z]);
  }
  poseAt(keep);
  const pos = new Float32Array(state.frames * 3);
  state.path.forEach(([x, z], i) => pos.set([x, groundUnder(x, z) + 0.004, z], 3 * i));
  const geo = new THREE.BufferGeometry();
  geo.setAttribute("position", new THREE.BufferAttribute(pos, 3));
  geo.setAttribute("color", new THREE.BufferAttribute(new Float32Array(state.frames * 3), 3));
  pathLine = new THREE.Line(geo, new THREE.LineBasicMaterial({ vertexColors: true }));
  pathLine.visible = $("trace").checked;
  scene.add(pathLine);
  paintPath();
}

function paintPath() {
  if (!pathLine) return;
  const col = pathLine.geometry.getAttribute("color");
  const c = new THREE.Color();
  for (let f = 0; f < state.frames; f++) {
    const age = state.frame - f;
    const w = age < 0 ? 0.18 : 0.25 + 0.75 * Math.exp(-age / PATH_FADE_FRAMES);
    c.copy(BG).lerp(INK, w);
    col.setXYZ(f, c.r, c.g, c.b);
  }
  col.needsUpdate = true;
}

// ---------------------------------------------------------------- camera views
function pathBox() {
  const xs = state.path.map((p) => p[0]);
  const zs = state.path.map((p) => p[1]);
  const cx = (Math.min(...xs) + Math.max(...xs)) / 2;
  const cz = (Math.min(...zs) + Math.max(...zs)) / 2;
  const span = Math.max(Math.max(...xs) - Math.min(...xs), Math.max(...zs) - Math.min(...zs), 1.5);
  return { cx, cz, span };
}

function setView(view) {
  // follow: the camera glides after the root; front / side / top: a fixed view of the whole
  // path (front faces the body's start, which looks along +z)
  state.view = view;
  $("view").value = view;
  if (!state.ready && !state.path.length) return;
  const { cx, cz, span } = pathBox();
  const d = 1.2 * span + 2.6;
  const lift = state.steps.length ? Math.max(...state.steps.map((s) => s.top)) / 2 : 0;
  if (view === "follow") {
    rootJoint.getWorldPosition(lastRoot);
    lastGround = groundUnder(lastRoot.x, lastRoot.z);
    controls.target.set(lastRoot.x, 0.9 + lastGround, lastRoot.z);
    camera.position.set(lastRoot.x + 2.6, 1.7 + lastGround, lastRoot.z + 3.6);
  } else if (view === "front") {
    controls.target.set(cx, 0.9 + lift, cz);
    camera.position.set(cx, 1.3 + lift, cz + d);
  } else if (view === "side") {
    controls.target.set(cx, 0.9 + lift, cz);
    camera.position.set(cx + d, 1.3 + lift, cz);
  } else if (view === "top") {
    controls.target.set(cx, 0, cz);
    camera.position.set(cx, 1.25 * span + 2.2, cz + 0.001);
  }
  controls.update();
  dirty = true;
}

function unload() {
  state.ready = false;
  state.loadedAt = null;
  state.renderedFrames = 0;
  if (mixer) mixer.stopAllAction();
  mixer = action = null;
  if (figure) figure.dispose();
  if (ghosts) {
    ghosts.traverse((o) => o.material && o.material.dispose());
    ghosts.removeFromParent();
  }
  if (motionScene) motionScene.removeFromParent();
  figure = ghosts = motionScene = null;
  bodyMeshes = [];
  $("ghosts").checked = false;
}

async function load(url) {
  showMessage(state.ready ? "" : "Loading motion…");
  const gltf = await new GLTFLoader().loadAsync(url);
  state.fetchedAt = Date.now();
  unload(); // the previous motion stays on screen until the new one is ready
  state.url = url;
  const extras = gltf.scene.userData || {};
  const clip = gltf.animations[0];
  if (!clip) throw new Error("the file has no animation");
  state.fps = extras.fps || 20;
  state.frames = extras.frames || Math.round(clip.duration * state.fps) + 1;
  state.duration = clip.duration;
  state.segments = extras.segments || [];
  state.keyframes = extras.keyframes || [];
  state.method = extras.method || null;
  state.steps = extras.steps || [];
  state.plays = 0;
  buildSteps();

  // a file with a body (extras.body) shows its skinned mesh; the bones are our own capsules
  bodyMeshes = [];
  gltf.scene.traverse((o) => {
    if (o.isSkinnedMesh && extras.body) {
      o.castShadow = true;
      o.frustumCulled = false; // its bounds are the rest pose's; the motion leaves them
      bodyMeshes.push(o);
    } else if (o.isMesh) o.visible = false;
  });
  state.hasBody = bodyMeshes.length > 0;
  scene.add(gltf.scene);
  motionScene = gltf.scene;
  const names = extras.joint_names || [];
  joints = [];
  gltf.scene.traverse((o) => {
    if (o.isBone) joints.push(o);
  });
  joints.sort((a, b) => names.indexOf(a.name) - names.indexOf(b.name));
  rootJoint = joints.find((j) => !(j.parent && j.parent.isBone)) || joints[0];

  mixer = new THREE.AnimationMixer(gltf.scene);
  action = mixer.clipAction(clip);
  action.setLoop(THREE.LoopOnce, 1);
  action.clampWhenFinished = true;
  action.play();
  figure = new Figure(joints);
  scene.add(figure.group);
  showBody();
  ghosts = buildGhosts(joints);
  buildPath();

  $("scrub").max = String(state.frames - 1);
  buildTrack();
  setTime(0);
  figure.update();
  $("controls").hidden = false;
  setView(state.view);
  showMessage("");
  resize();
  setPlaying(params.get("autoplay") !== "0");
  busy = null; // the request brought this motion: it plays now, not when the page says idle
  state.ready = true;
  dirty = true;
}

// ---------------------------------------------------------------- controls
$("play").addEventListener("click", () => {
  if (!state.playing && state.time >= state.duration) setTime(0);
  setPlaying(!state.playing);
  broadcast("control");
});
$("scrub").addEventListener("input", (e) => {
  setTime(Number(e.target.value) / state.fps);
  broadcast("control");
});
$("speed").addEventListener("change", (e) => {
  state.speed = Number(e.target.value);
  broadcast("control");
});
$("loop").addEventListener("change", (e) => {
  state.loop = e.target.checked;
  broadcast("control");
});
$("view").addEventListener("change", (e) => setView(e.target.value));
$("trace").addEventListener("change", (e) => {
  if (pathLine) pathLine.visible = e.target.checked;
  dirty = true;
});
function toggleFullscreen() {
  // inside the demo page the viewer is an iframe: its parent puts the frame in fullscreen
  if (window.parent !== window) {
    window.parent.postMessage({ type: "mms-fullscreen" }, location.origin);
  } else if (document.fullscreenElement) {
    document.exitFullscreen();
  } else {
    document.documentElement.requestFullscreen().catch(() => {});
  }
}
$("fullscreen").addEventListener("click", toggleFullscreen);

// ---------------------------------------------------------------- video
// One play-through from the first frame, drawn frame by frame with the current camera and
// figure, into a WebM through the browser's MediaRecorder. The canvas stream is fed by hand
// (captureStream(0) + requestFrame), one video frame per motion frame, paced at the motion's
// own rate: a slow machine then records late, never drops or repeats a frame. The recorder
// stamps frames with the time they were taken, so where drawing a frame takes longer than a
// frame lasts (software WebGL on a busy 2-core machine: about 0.13 s against 0.05 s) the
// video plays slower than the motion; on a machine that keeps up it plays in real time.
function videoName() {
  const file = (state.url || "motion.glb").split("?")[0].split("/").pop() || "motion.glb";
  return file.replace(/\.glb$/i, "") + ".webm";
}

async function recordVideo() {
  if (!state.ready || state.recording) return;
  const mime = ["video/webm;codecs=vp8", "video/webm;codecs=vp9", "video/webm"].find((m) =>
    window.MediaRecorder && MediaRecorder.isTypeSupported(m),
  );
  if (!mime) {
    showMessage("This browser cannot record video.", true);
    return;
  }
  const stream = renderer.domElement.captureStream(0);
  const track = stream.getVideoTracks()[0];
  const rec = new MediaRecorder(stream, { mimeType: mime, videoBitsPerSecond: 4_000_000 });
  const chunks = [];
  rec.ondataavailable = (e) => e.data.size && chunks.push(e.data);
  const stopped = new Promise((resolve) => (rec.onstop = resolve));
  const wasPlaying = state.playing;
  setPlaying(false);
  state.recording = true;
  state.recordedFrames = 0;
  $("record").classList.add("recording");
  rec.start();
  await new Promise((r) => setTimeout(r, 400));
  const t0 = performance.now();
  for (let k = 0; k < state.frames; k++) {
    const due = t0 + (1000 * k) / state.fps;
    await new Promise((r) => setTimeout(r, Math.max(0, due - performance.now())));
    setTime(k / state.fps);
    figure.update();
    renderer.render(scene, camera);
    track.requestFrame();
    // the stream takes the canvas at the next paint: drawing the next frame before it
    // would replace this one, so wait for two paints (on a slow machine the pacing above
    // is already behind and would not wait at all)
    for (let i = 0; i < 2; i++) await new Promise((r) => requestAnimationFrame(() => r()));
    state.recordedFrames = k + 1;
  }
  // the encoder works behind the stream: give the last frames time to reach it
  await new Promise((r) => setTimeout(r, 500));
  rec.stop();
  await stopped;
  track.stop();
  const blob = new Blob(chunks, { type: mime.split(";")[0] });
  const a = document.createElement("a");
  a.href = URL.createObjectURL(blob);
  a.download = videoName();
  document.body.appendChild(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 60_000);
  state.recording = false;
  $("record").classList.remove("recording");
  setPlaying(wasPlaying);
  dirty = true;
}
$("record").addEventListener("click", () => {
  recordVideo().catch((err) => {
    state.recording = false;
    $("record").classList.remove("recording");
    showMessage(`Could not record the video: ${err.message || err}`, true);
  });
});
document.addEventListener("fullscreenchange", () => setTimeout(resize, 50));
$("body").addEventListener("change", showBody);
$("ghosts").addEventListener("change", (e) => {
  if (ghosts) ghosts.visible = e.target.checked;
  dirty = true;
});
window.addEventListener("keydown", (e) => {
  if (e.code === "Space" && state.ready) {
    e.preventDefault();
    $("play").click();
  } else if (e.key === "f" && !e.ctrlKey && !e.metaKey && e.target.tagName !== "SELECT") {
    toggleFullscreen();
  }
});
// ---------------------------------------------------------------- synchronised viewers
// viewer.html?sync=NAME joins a BroadcastChannel with the other viewers of the same name (a
// user study's A and B): any user action is mirrored, and the viewer with &lead=1 sends its
// clock a few times a second so the others stay within a frame of it.
const sync = params.get("sync") ? new BroadcastChannel(`mms-sync-${params.get("sync")}`) : null;
const leads = params.get("lead") === "1";
function broadcast(type) {
  if (sync && state.ready) {
    sync.postMessage({ type, time: state.time, playing: state.playing, speed: state.speed, loop: state.loop });
  }
}
if (sync) {
  sync.onmessage = (e) => {
    const m = e.data || {};
    if (!state.ready || (m.type !== "control" && m.type !== "clock")) return;
    if (m.type === "control") {
      state.speed = m.speed;
      $("speed").value = String(m.speed);
      state.loop = m.loop;
      $("loop").checked = m.loop;
    }
    if (m.type === "control" || Math.abs(m.time - state.time) > 0.5 / state.fps) setTime(m.time);
    if (m.playing !== state.playing) setPlaying(m.playing);
    dirty = true;
  };
  if (leads) setInterval(() => broadcast("clock"), 250);
}
if (params.get("keyframes") === "0") $("ghost-label").hidden = true;
// a page that cannot put this frame in fullscreen (the user study) asks for no button
if (params.get("fullscreen") === "0") $("fullscreen").hidden = true;
state.play = () => setPlaying(true);
state.pause = () => setPlaying(false);
state.setTime = (t) => {
  setTime(t);
  dirty = true; // a script's scrub is drawn too (the scrubber's own input marks it)
};
state.setView = setView;
// the pose on show: each joint's world position [x, y, z], in the file's joint order
state.jointPositions = () => {
  if (!timeShown) showTime(); // the pose at the clock's time, drawn or not
  return joints.map((j) => j.getWorldPosition(new THREE.Vector3()).toArray());
};
// the step boxes drawn (a motion on stairs): each one's world bounds {min: [x, y, z], max: [...]}
state.stepBoxes = () =>
  stepGroup
    ? stepGroup.children.map((b) => {
        const bb = new THREE.Box3().setFromObject(b);
        return { min: bb.min.toArray(), max: bb.max.toArray(), visible: b.visible };
      })
    : [];
state.record = recordVideo;
Object.defineProperty(state, "canvasWidth", { get: () => renderer.domElement.width });
Object.defineProperty(state, "canvasHeight", { get: () => renderer.domElement.height });
if (["front", "side", "top", "follow"].includes(params.get("view"))) state.view = params.get("view");

// ---------------------------------------------------------------- loop
// Render on demand, at most MAX_FPS: the motion is 20 fps, and a page that redraws a static
// scene 60 times a second takes CPU from everything else (in software-GL browsers, from the
// very server generating the next motion).
// A page may ask for fewer (window.MMS_MAX_FPS; the browser tests ask for 2: on a 2-core VM's
// software GL a drawn frame took about 100 ms of the page's thread, which its Gradio page needs).
const MAX_FPS = Math.min(Math.max(Number(window.MMS_MAX_FPS) || 30, 1), 30);
let lastDraw = -Infinity;
controls.addEventListener("change", () => (dirty = true));
window.addEventListener("resize", () => (dirty = true));
for (const id of ["scrub", "speed", "loop", "view", "trace", "ghosts", "play", "body"]) {
  $(id).addEventListener("input", () => (dirty = true));
  $(id).addEventListener("click", () => (dirty = true));
}
const timer = new THREE.Timer();
timer.connect(document); // the clock stops while the page is hidden
function tick(now) {
  requestAnimationFrame(tick);
  timer.update(now);
  // nothing is drawn while a motion is being generated, not even the follow camera's glide
  // (at a software-GL browser's 10 frames a second it lasted seconds after the pause): each
  // frame took the page's one thread from the request the page is waiting on
  if (busy) return;
  const dt = Math.min(timer.getDelta(), 0.1);
  if (state.ready && state.playing) {
    let t = state.time + dt * state.speed;
    if (t > state.duration) {
      state.plays += 1;
      if (state.loop) t = state.duration > 0 ? t % state.duration : 0;
      else {
        t = state.duration;
        setPlaying(false);
      }
    }
    if (state.playing) moveTime(t);
    else setTime(t); // stopped at the end: the last pose and the clock show at once
    dirty = true;
  }
  const following = state.ready && state.view === "follow";
  if (following) {
    // the camera keeps its offset and glides after the root
    rootJoint.getWorldPosition(tmpA);
    const dx = (tmpA.x - lastRoot.x) * 0.15;
    const dz = (tmpA.z - lastRoot.z) * 0.15;
    if (Math.abs(dx) + Math.abs(dz) > 1e-5) {
      lastRoot.x += dx;
      lastRoot.z += dz;
      controls.target.x += dx;
      controls.target.z += dz;
      camera.position.x += dx;
      camera.position.z += dz;
      dirty = true;
    }
    // on stairs it climbs (or descends) with the ground under the body
    const dy = state.steps.length ? (groundUnder(tmpA.x, tmpA.z) - lastGround) * 0.15 : 0;
    if (Math.abs(dy) > 1e-5) {
      lastGround += dy;
      controls.target.y += dy;
      camera.position.y += dy;
      dirty = true;
    }
  }
  controls.update();
  if (!dirty || document.hidden || (now ?? 0) - lastDraw < 1000 / MAX_FPS - 2) return;
  lastDraw = now ?? 0;
  dirty = false;
  if (state.ready) {
    if (!timeShown) showTime();
    figure.update();
    sun.position.set(controls.target.x + 3, 6, controls.target.z + 2);
    sun.target.position.set(controls.target.x, 0, controls.target.z);
  }
  renderer.render(scene, camera);
  if (state.ready) {
    state.renderedFrames += 1;
    if (state.loadedAt === null) state.loadedAt = Date.now();
  }
}
requestAnimationFrame(tick);

let loading = 0; // loads in flight: the page's "idle" may come before the new motion is parsed
function loadOrReport(url) {
  state.error = null;
  state.requestedAt = Date.now();
  loading += 1;
  load(url)
    .catch((err) => {
      busy = null; // no motion comes: the page is no longer waiting on this one
      state.error = `Could not load the motion: ${err.message || err}`;
      showMessage(state.error, true);
    })
    .finally(() => {
      loading -= 1;
    });
}

// The embedding page sends new motions by message, so the viewer (and three.js) load once.
const IDLE_MESSAGE = $("message").textContent;
window.addEventListener("message", (e) => {
  if (e.origin !== location.origin || !e.data) return;
  if (e.data.type === "mms-busy") {
    // a new motion is being generated: hold still (and free the CPU) until it arrives
    busy = { playing: busy ? busy.playing : state.playing };
    if (state.ready) setPlaying(false);
    showMessage("Generating…");
  } else if (e.data.type === "mms-idle") {
    // the request has ended; when it was refused no motion comes, so the last one plays on.
    // While its motion is still being fetched and parsed, the load ends the busy state
    // itself: resuming the old motion here would draw it again during the parse
    if (loading > 0) return;
    const was = busy;
    busy = null;
    if ($("message").textContent === "Generating…") showMessage(state.ready ? "" : IDLE_MESSAGE);
    if (was && was.playing && state.ready && !state.playing) setPlaying(true);
  } else if (e.data.type === "mms-load" && e.data.glb) {
    if (e.data.glb !== state.url || !state.ready) loadOrReport(e.data.glb);
    else showMessage("");
  }
});
if (state.url) loadOrReport(state.url);
