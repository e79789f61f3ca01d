// The learning report's animation (report.html): the surface motion of each track of the
// inlined animation data, drawn with three.js (inlined as text, imported from a blob: URL so
// that the page needs no network and no second file). Drag to turn the view; the layout button
// switches between side by side and overlaid surfaces.
// When done, <html data-status> is "ok" and data-rendered-colours counts the distinct colours
// read back from the first rendered frame (a blank canvas has one): the report test reads both.
const statusOf = (s) => { if (document.documentElement.dataset.status !== "error") document.documentElement.dataset.status = s; };

function decodeFloats(base64) {
  const bytes = Uint8Array.from(atob(base64), (c) => c.charCodeAt(0));
  return new Float32Array(bytes.buffer);
}

async function main() {
  const data = JSON.parse(document.getElementById("animation-data").textContent);
  const container = document.getElementById("viewer");
  if (!data || !container) { statusOf("ok"); return; }
  const source = document.getElementById("three-module").textContent;
  const url = URL.createObjectURL(new Blob([source], { type: "text/javascript" }));
  const THREE = await import(url);
  URL.revokeObjectURL(url);

  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(1);
  const width = container.clientWidth, height = container.clientHeight;
  renderer.setSize(width, height, false);
  container.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xffffff);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x888888, 2.0));
  const sun = new THREE.DirectionalLight(0xffffff, 1.5);
  sun.position.set(1, 2, 3);
  scene.add(sun);
  const pivot = new THREE.Group();
  scene.add(pivot);

  // Grey for the truth (the first of several surfaces), orange for the learned model, then more.
  const palette = [0x9a9a9a, 0xe0701a, 0x2a7bd6, 0x3aa04a];
  const surfaces = data.tracks.filter((u) => !u.points).length;
  const colours = surfaces > 1 ? palette : palette.slice(1);
  const tracks = data.tracks.map((t, i) => {
    const values = decodeFloats(t.positions);
    const geometry = new THREE.BufferGeometry();
    const position = new THREE.BufferAttribute(values.slice(0, 3 * t.count), 3);
    position.setUsage(THREE.DynamicDrawUsage);
    geometry.setAttribute("position", position);
    let object, solid = null, wire = null;
    if (t.points) {
      object = new THREE.Points(geometry, new THREE.PointsMaterial({ color: 0x111111, size: 5, sizeAttenuation: false }));
    } else {
      geometry.setIndex(data.faces);
      geometry.computeVertexNormals();
      solid = new THREE.MeshStandardMaterial({ color: colours[i % colours.length], roughness: 0.6, side: THREE.DoubleSide });
      wire = new THREE.MeshBasicMaterial({ color: colours[i % colours.length], wireframe: true });
      object = new THREE.Mesh(geometry, solid);
    }
    pivot.add(object);
    const legend = document.getElementById("legend");
    if (legend) {
      const swatch = document.createElement("span");
      swatch.style.background = "#" + (t.points ? 0x111111 : colours[i % colours.length]).toString(16).padStart(6, "0");
      legend.append(swatch, t.label + (t.points ? " (points)" : ""));
    }
    return { track: t, values, geometry, position, points: t.points, object, solid, wire };
  });

  // Two or more surfaces (truth and learned) are shown side by side, or overlaid with the first
  // (the truth) as a wireframe. Side by side they are offset along the horizontal or vertical
  // axis (whichever the motion spans less) by 1.25 times the motion's extent along it.
  const motion = new THREE.Box3();
  for (const t of tracks) {
    if (t.points) continue;
    const v = t.values;
    for (let k = 0; k < v.length; k += 3) motion.expandByPoint(new THREE.Vector3(v[k], v[k + 1], v[k + 2]));
  }
  const extent = motion.getSize(new THREE.Vector3());
  const axis = extent.y <= extent.x ? new THREE.Vector3(0, -1.25 * extent.y, 0) : new THREE.Vector3(1.25 * extent.x, 0, 0);
  const layout = document.getElementById("layout");
  let sideBySide = surfaces > 1;
  function arrange() {
    let k = 0;
    for (const t of tracks) {
      if (t.points) continue;
      t.object.position.copy(axis).multiplyScalar(sideBySide ? k : 0);
      t.object.material = !sideBySide && k === 0 && surfaces > 1 ? t.wire : t.solid;
      ++k;
    }
    if (layout) layout.textContent = sideBySide ? "overlay" : "side by side";
  }
  arrange();
  if (layout) {
    layout.hidden = surfaces < 2;
    layout.addEventListener("click", () => { sideBySide = !sideBySide; arrange(); });
  }

  // Centre the first frame in the view.
  const box = new THREE.Box3();
  for (const t of tracks) {
    if (t.points) {
      t.geometry.computeBoundingBox();
      box.union(t.geometry.boundingBox);
    } else {
      box.union(motion.clone().translate(t.object.position));
    }
  }
  const centre = box.getCenter(new THREE.Vector3());
  const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 1e-6);
  pivot.position.copy(centre).negate();
  const holder = new THREE.Group();
  scene.remove(pivot); holder.add(pivot); scene.add(holder);
  const camera = new THREE.PerspectiveCamera(35, width / height, radius / 100, radius * 100);
  camera.position.set(0.6 * radius, 0.9 * radius, 3.2 * radius);
  camera.lookAt(0, 0, 0);
  holder.rotation.set(0.25, -0.5, 0);

  let dragging = null;
  renderer.domElement.addEventListener("pointerdown", (e) => { dragging = { x: e.clientX, y: e.clientY }; });
  window.addEventListener("pointerup", () => { dragging = null; });
  window.addEventListener("pointermove", (e) => {
    if (!dragging) return;
    holder.rotation.y += 0.01 * (e.clientX - dragging.x);
    holder.rotation.x += 0.01 * (e.clientY - dragging.y);
    dragging = { x: e.clientX, y: e.clientY };
  });

  const slider = document.getElementById("frame");
  const label = document.getElementById("frame-label");
  const play = document.getElementById("play");
  slider.max = String(data.frames - 1);
  let playing = true, frame = 0, last = performance.now();
  play.addEventListener("click", () => { playing = !playing; play.textContent = playing ? "pause" : "play"; });
  slider.addEventListener("input", () => { frame = Number(slider.value); playing = false; play.textContent = "play"; });

  function show(f) {
    for (const t of tracks) {
      const n = 3 * t.track.count;
      t.position.array.set(t.values.subarray(f * n, (f + 1) * n));
      t.position.needsUpdate = true;
      if (!t.points) t.geometry.computeVertexNormals();
    }
    slider.value = String(f);
    label.textContent = "t = " + (f * data.frame_seconds).toFixed(3) + " s (frame " + f * data.stride + ")";
  }

  show(0);
  renderer.render(scene, camera);
  const gl = renderer.getContext();
  const pixels = new Uint8Array(4 * width * height);
  gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
  const seen = new Set();
  for (let i = 0; i < pixels.length && seen.size < 64; i += 4 * 7)
    seen.add((pixels[i] << 16) | (pixels[i + 1] << 8) | pixels[i + 2]);
  document.documentElement.dataset.renderedColours = String(seen.size);

  renderer.setAnimationLoop((now) => {
    if (playing && now - last > 1000 * data.frame_seconds) {
      frame = (frame + 1) % data.frames;
      last = now;
      show(frame);
    }
    renderer.render(scene, camera);
  });
  statusOf("ok");
}

main().catch((e) => reportError(e && e.stack || e));
