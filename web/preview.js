// The toolpath preview: the whole program from its canonical commands (feeds
// solid, rapids dashed), the tool where the machine is, and the way the tool
// has gone while the program ran drawn over it in another colour. three.js
// (vendored at build time) where WebGL works; a 2D top view where it does not.
import { parseCanon } from './canon.js';

const COLORS = { feed: 0x4fb3ff, rapid: 0xe0a040, cut: 0x5cff8a, tool: 0xff4060 };
const css = (c) => '#' + c.toString(16).padStart(6, '0');
const TRAIL_MAX = 200000;

export function createPreview(box, canvas2d) {
  const state = { path: null, trail: [], tool: null, impl: null, errorsShown: false };
  const api = {
    kind: 'none',
    setCanon(text) {
      state.path = parseCanon(text || '');
      state.trail = [];
      if (state.impl) state.impl.setPath(state.path);
    },
    // p: work position (machine minus G5x) per axis; the tool's length
    // offset as the program gives it, so that the tip meets the path
    setTool(p, axes, moving, toolNo) {
      const tlo = (state.path && state.path.tlo[toolNo]) || [0, 0, 0];
      const xyz = [0, 1, 2].map((i) => (axes[i] ? p[i] - tlo[i] : 0));
      const last = state.trail[state.trail.length - 1];
      if (moving && (!last || Math.hypot(xyz[0] - last[0], xyz[1] - last[1], xyz[2] - last[2]) > 0.02)) {
        if (state.trail.length < TRAIL_MAX) state.trail.push(xyz);
      }
      state.tool = xyz;
      if (state.impl) state.impl.setTool(xyz, state.trail);
    },
  };
  import('three')
    .then((THREE) => import('./vendor/OrbitControls.js').then((oc) => threeView(THREE, oc.OrbitControls, box, canvas2d, state)))
    .catch(() => twoDView(canvas2d, state))
    .then((impl) => {
      state.impl = impl;
      api.kind = impl.kind;
      if (state.path) impl.setPath(state.path);
      if (state.tool) impl.setTool(state.tool, state.trail);
    });
  return api;
}

function threeView(THREE, OrbitControls, box, canvas2d, state) {
  let renderer;
  try {
    renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  } catch (e) {
    return twoDView(canvas2d, state);
  }
  canvas2d.remove();
  box.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x0b0d10);
  const camera = new THREE.PerspectiveCamera(40, 1, 0.1, 100000);
  camera.up.set(0, 0, 1);
  const controls = new OrbitControls(camera, renderer.domElement);
  const group = new THREE.Group();
  scene.add(group);
  scene.add(new THREE.AxesHelper(10));
  const tool = new THREE.Mesh(new THREE.ConeGeometry(1.5, 6, 16), new THREE.MeshBasicMaterial({ color: COLORS.tool }));
  tool.rotation.x = -Math.PI / 2;       // tip down (-Z), the cone's axis along Z
  tool.geometry.translate(0, 3, 0);     // the tip at the tool point
  scene.add(tool);
  const trailGeo = new THREE.BufferGeometry();
  trailGeo.setAttribute('position', new THREE.BufferAttribute(new Float32Array(TRAIL_MAX * 3), 3));
  trailGeo.setDrawRange(0, 0);
  const trail = new THREE.Line(trailGeo, new THREE.LineBasicMaterial({ color: COLORS.cut, linewidth: 2, depthTest: false }));
  trail.frustumCulled = false;
  trail.renderOrder = 2;
  scene.add(trail);
  let trailDrawn = 0;

  let dirty = true, viewMoved = false, last = 0;
  function resize() {
    const w = box.clientWidth, h = box.clientHeight;
    renderer.setSize(w, h, false);
    renderer.domElement.style.width = '100%';
    renderer.domElement.style.height = '100%';
    camera.aspect = w / Math.max(1, h);
    camera.updateProjectionMatrix();
    viewMoved = true;   // a resized canvas is blank until drawn again
  }
  new ResizeObserver(resize).observe(box);
  resize();

  function lines(arr, material) {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(arr, 3));
    const l = new THREE.LineSegments(g, material);
    if (material.isLineDashedMaterial) l.computeLineDistances();
    return l;
  }

  // At most 20 frames a second for the moving tool: software WebGL on a small
  // panel PC would otherwise take the CPU the status and the DRO need.
  function draw(now) {
    controls.update();
    if (viewMoved || (dirty && now - last >= 50)) {
      renderer.render(scene, camera);
      dirty = viewMoved = false;
      last = now;
    }
    requestAnimationFrame(draw);
  }
  controls.addEventListener('change', () => { viewMoved = true; });
  requestAnimationFrame(draw);

  return {
    kind: 'webgl',
    setPath(p) {
      group.clear();
      if (p.feed.length) group.add(lines(p.feed, new THREE.LineBasicMaterial({ color: COLORS.feed })));
      if (p.rapid.length) group.add(lines(p.rapid, new THREE.LineDashedMaterial({ color: COLORS.rapid, dashSize: 1.5, gapSize: 1.2 })));
      trailDrawn = 0;
      trailGeo.setDrawRange(0, 0);
      if (isFinite(p.min[0])) {
        const c = p.min.map((v, i) => (v + p.max[i]) / 2);
        const size = Math.max(...p.max.map((v, i) => v - p.min[i]), 10);
        controls.target.set(c[0], c[1], c[2]);
        camera.position.set(c[0] - size * 0.6, c[1] - size * 1.3, c[2] + size * 1.1);
        controls.update();
      }
      dirty = true;
    },
    setTool(xyz, trailPts) {
      tool.position.set(xyz[0], xyz[1], xyz[2]);
      const pos = trailGeo.attributes.position;
      if (trailPts.length < trailDrawn) trailDrawn = 0;
      for (let i = trailDrawn; i < trailPts.length; i++) pos.setXYZ(i, ...trailPts[i]);
      if (trailPts.length !== trailDrawn) {
        pos.needsUpdate = true;
        trailGeo.setDrawRange(0, trailPts.length);
        trailDrawn = trailPts.length;
      }
      dirty = true;
    },
  };
}

// A top view (XY) on a 2D canvas: the same colours and dashes.
function twoDView(canvas, state) {
  const ctx = canvas.getContext('2d');
  let view = null;
  function fit() {
    const p = state.path;
    const w = canvas.clientWidth, h = canvas.clientHeight;
    canvas.width = w * devicePixelRatio;
    canvas.height = h * devicePixelRatio;
    if (!p || !isFinite(p.min[0])) { view = null; return; }
    const sx = p.max[0] - p.min[0] || 10, sy = p.max[1] - p.min[1] || 10;
    const s = 0.9 * Math.min(w / sx, h / sy) * devicePixelRatio;
    view = { s, ox: canvas.width / 2 - s * (p.min[0] + sx / 2), oy: canvas.height / 2 + s * (p.min[1] + sy / 2) };
  }
  const X = (x) => view.ox + view.s * x, Y = (y) => view.oy - view.s * y;
  function segs(arr, color, dash) {
    ctx.strokeStyle = css(color);
    ctx.setLineDash(dash);
    ctx.beginPath();
    for (let i = 0; i < arr.length; i += 6) { ctx.moveTo(X(arr[i]), Y(arr[i + 1])); ctx.lineTo(X(arr[i + 3]), Y(arr[i + 4])); }
    ctx.stroke();
  }
  function draw() {
    ctx.fillStyle = '#0b0d10';
    ctx.fillRect(0, 0, canvas.width, canvas.height);
    if (!view) return;
    ctx.lineWidth = devicePixelRatio;
    segs(state.path.feed, COLORS.feed, []);
    segs(state.path.rapid, COLORS.rapid, [6, 5]);
    if (state.trail.length > 1) {
      ctx.strokeStyle = css(COLORS.cut);
      ctx.lineWidth = 2 * devicePixelRatio;
      ctx.setLineDash([]);
      ctx.beginPath();
      state.trail.forEach((p, i) => (i ? ctx.lineTo(X(p[0]), Y(p[1])) : ctx.moveTo(X(p[0]), Y(p[1]))));
      ctx.stroke();
    }
    if (state.tool) {
      ctx.fillStyle = css(COLORS.tool);
      ctx.beginPath();
      ctx.arc(X(state.tool[0]), Y(state.tool[1]), 5 * devicePixelRatio, 0, 2 * Math.PI);
      ctx.fill();
    }
  }
  new ResizeObserver(() => { fit(); draw(); }).observe(canvas);
  return {
    kind: '2d',
    setPath() { fit(); draw(); },
    setTool() { draw(); },
  };
}
