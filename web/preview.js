// The toolpath preview: the whole program from its canonical commands (feeds
// solid, rapids dashed), the part already cut in another colour than what
// remains (progress.js says how far), the tool where the machine is, a grid
// and the travel box, seen from the top, front, side or at an angle, zoomed
// with the wheel and panned by dragging. three.js (vendored at build time)
// where WebGL works; preview-2d.js where it does not.
import { parseCanon } from './canon.js';
import { twoDView } from './preview-2d.js';
import { COLORS, VIEWS, travelBox, extentsBox, fitBox } from './preview-common.js';

const TRAIL_MAX = 200000;

export function createPreview(box, canvas2d) {
  const state = { path: null, trail: [], tool: null, impl: null, done: 0, view: 'iso', travel: null };
  const api = {
    kind: 'none',
    // returns the parsed path: the panel follows the tool along it
    setCanon(text) {
      state.path = parseCanon(text || '');
      state.trail = [];
      state.done = 0;
      if (state.impl) state.impl.setPath(state.path);
      return state.path;
    },
    // the machine's travel in work coordinates, [min, max] (null: none
    // known, the box is the program's extents)
    setTravel(t) { state.travel = t; if (state.impl && state.path) state.impl.setPath(state.path); },
    // xyz: the tool's point on the drawing (canon.js's toolPoint); moving:
    // whether its way so far is drawn
    setTool(xyz, moving) {
      const last = state.trail[state.trail.length - 1];
      if (moving && (!last || Math.hypot(xyz[0] - last[0], xyz[1] - last[1], xyz[2] - last[2]) > 0.02)) {
        if (state.trail.length < TRAIL_MAX) state.trail.push(xyz);
      }
      state.tool = xyz;
      if (state.impl) state.impl.setTool(xyz, state.trail);
    },
    // segments before done (in the program's order) are drawn as cut
    setDone(done) {
      if (done === state.done) return;
      state.done = done;
      if (state.impl) state.impl.setDone(done);
    },
    setView(name) { state.view = name; if (state.impl) state.impl.setView(name); },
    // for the test and the curious: the view's name, the camera's view
    // matrix (16 numbers, column-major) and its distance to what it looks at
    view() { return state.impl ? state.impl.view() : null; },
    // the box drawn: [min, max] in the drawing's coordinates, or null
    box() { return travelBox(state.path, state.travel); },
  };
  for (const b of box.querySelectorAll('[data-view]'))
    b.addEventListener('click', () => api.setView(b.dataset.view));
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
  box.prepend(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(COLORS.bg);
  const camera = new THREE.PerspectiveCamera(40, 1, 0.1, 100000);
  camera.up.set(0, 0, 1);
  const controls = new OrbitControls(camera, renderer.domElement);
  // A machinist drags the drawing to move it, as in LinuxCNC's AXIS; turning
  // it is the right button (or two fingers), and the view buttons.
  controls.mouseButtons = { LEFT: THREE.MOUSE.PAN, MIDDLE: THREE.MOUSE.DOLLY, RIGHT: THREE.MOUSE.ROTATE };
  controls.touches = { ONE: THREE.TOUCH.PAN, TWO: THREE.TOUCH.DOLLY_ROTATE };
  controls.screenSpacePanning = true;
  const group = new THREE.Group();      // the program: path, grid, travel box
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
  let feedColors = null, coloured = 0, size = 10, centre = [0, 0, 0], viewName = state.view;

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

  // Feed segments before done in the cut colour, the rest in the feed colour:
  // only the range that changed is written.
  function colourDone(done) {
    if (!feedColors || !state.path) return;
    const segs = state.path.segs;
    const from = Math.min(coloured, done), to = Math.min(Math.max(coloured, done), segs.length);
    const cut = new THREE.Color(COLORS.cut), todo = new THREE.Color(COLORS.feed);
    for (let k = from; k < to; k++) {
      const s = segs[k];
      if (!s.feed) continue;
      const c = k < done ? cut : todo;
      feedColors.setXYZ(2 * s.i, c.r, c.g, c.b);
      feedColors.setXYZ(2 * s.i + 1, c.r, c.g, c.b);
    }
    feedColors.needsUpdate = true;
    coloured = done;
    dirty = true;
  }

  function setView(name) {
    const v = VIEWS[name] || VIEWS.iso;
    viewName = VIEWS[name] ? name : 'iso';
    const d = size * 1.5;
    controls.target.set(...centre);
    // a view straight down Z is kept a hair off the axis: OrbitControls
    // cannot tell which way is up when looking along camera.up
    camera.position.set(centre[0] + d * v[0], centre[1] + d * v[1] - (v[0] === 0 && v[1] === 0 ? 1e-3 * d : 0), centre[2] + d * v[2]);
    controls.update();
    viewMoved = true;
  }

  return {
    kind: 'webgl',
    setPath(p) {
      group.clear();
      feedColors = null;
      coloured = 0;
      if (p.feed.length) {
        const l = lines(p.feed, new THREE.LineBasicMaterial({ vertexColors: true }));
        const n = p.feed.length / 3, col = new Float32Array(3 * n);
        const c = new THREE.Color(COLORS.feed);
        for (let i = 0; i < n; i++) col.set([c.r, c.g, c.b], 3 * i);
        feedColors = new THREE.BufferAttribute(col, 3);
        l.geometry.setAttribute('color', feedColors);
        group.add(l);
      }
      if (p.rapid.length) group.add(lines(p.rapid, new THREE.LineDashedMaterial({ color: COLORS.rapid, dashSize: 1.5, gapSize: 1.2 })));
      // the program's extents, the machine's travel around them (dimmer),
      // and the view fitted to the program
      const box3 = ([lo, hi]) => new THREE.Box3(new THREE.Vector3(...lo), new THREE.Vector3(...hi));
      const ext = extentsBox(p), tb = fitBox(p, state.travel);
      if (ext) group.add(new THREE.Box3Helper(box3(ext), new THREE.Color(COLORS.box)));
      if (state.travel) group.add(new THREE.Box3Helper(box3(state.travel), new THREE.Color(COLORS.travel)));
      if (tb) {
        const [lo, hi] = tb;
        // a 10 mm grid on the work's Z0 plane, over the box and the origin
        const span = Math.max(hi[0], hi[1], 0) - Math.min(lo[0], lo[1], 0);
        const cells = Math.max(2, Math.ceil(span / 10) + 2);
        const grid = new THREE.GridHelper(cells * 10, cells, COLORS.gridMajor, COLORS.grid);
        grid.rotation.x = Math.PI / 2;   // GridHelper lies in XZ; the table is XY
        const mid = (a, b) => Math.round(((Math.min(a, 0) + Math.max(b, 0)) / 2) / 10) * 10;
        grid.position.set(mid(lo[0], hi[0]), mid(lo[1], hi[1]), 0);
        group.add(grid);
        centre = lo.map((v, i) => (v + hi[i]) / 2);
        size = Math.max(...hi.map((v, i) => v - lo[i]), 10);
        setView(viewName);
      }
      trailDrawn = 0;
      trailGeo.setDrawRange(0, 0);
      colourDone(state.done);
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
    setDone: colourDone,
    setView,
    view() {
      camera.updateMatrixWorld();
      return { name: viewName, matrix: [...camera.matrixWorldInverse.elements],
               distance: camera.position.distanceTo(controls.target),
               target: controls.target.toArray() };
    },
  };
}
