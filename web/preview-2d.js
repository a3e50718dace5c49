// The preview without WebGL: the same drawing on a 2D canvas, as an
// orthographic projection for each of the views (the iso one a plain
// axonometric one), zoomed with the wheel and panned by dragging.
import { COLORS, css, VIEWS, extentsBox, fitBox } from './preview-common.js';

// Screen right and screen up, as work directions, for each view.
const AXES2D = {
  top: [[1, 0, 0], [0, 1, 0]],
  front: [[1, 0, 0], [0, 0, 1]],
  side: [[0, 1, 0], [0, 0, 1]],
  iso: [[0.894, -0.447, 0], [0.3, 0.6, 0.74]],
};

export function twoDView(canvas, state) {
  const ctx = canvas.getContext('2d');
  let fitted = null, zoom = 1, pan = [0, 0], viewName = VIEWS[state.view] ? state.view : 'iso';
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  function fit() {
    canvas.width = canvas.clientWidth * devicePixelRatio;
    canvas.height = canvas.clientHeight * devicePixelRatio;
    const tb = fitBox(state.path, state.travel);
    if (!tb) { fitted = null; return; }
    const [r, u] = AXES2D[viewName];
    const corners = [];
    for (let i = 0; i < 8; i++) corners.push([0, 1, 2].map((k) => (i >> k) & 1 ? tb[1][k] : tb[0][k]));
    const xs = corners.map((c) => dot(c, r)), ys = corners.map((c) => dot(c, u));
    const sx = Math.max(...xs) - Math.min(...xs) || 10, sy = Math.max(...ys) - Math.min(...ys) || 10;
    fitted = { s: 0.85 * Math.min(canvas.width / sx, canvas.height / sy),
               cx: (Math.max(...xs) + Math.min(...xs)) / 2, cy: (Math.max(...ys) + Math.min(...ys)) / 2, box: tb };
  }
  function project(p) {
    const [r, u] = AXES2D[viewName], s = fitted.s * zoom;
    return [canvas.width / 2 + pan[0] + s * (dot(p, r) - fitted.cx), canvas.height / 2 + pan[1] - s * (dot(p, u) - fitted.cy)];
  }
  function seg(a, b) { const p = project(a), q = project(b); ctx.moveTo(p[0], p[1]); ctx.lineTo(q[0], q[1]); }
  function draw() {
    ctx.fillStyle = css(COLORS.bg);
    ctx.fillRect(0, 0, canvas.width, canvas.height);
    if (!fitted) return;
    const path = state.path || { segs: [], feed: [], rapid: [] }, lw = devicePixelRatio;
    ctx.lineWidth = lw;
    // the 12 edges of the program's extents, and of the travel around them
    ctx.setLineDash([]);
    for (const [bx, color] of [[state.travel, COLORS.travel], [extentsBox(state.path), COLORS.box]]) {
      if (!bx) continue;
      const [lo, hi] = bx;
      ctx.strokeStyle = css(color);
      ctx.beginPath();
      for (let i = 0; i < 8; i++) for (let k = 0; k < 3; k++) {
        if ((i >> k) & 1) continue;
        const a = [0, 1, 2].map((j) => (i >> j) & 1 ? hi[j] : lo[j]);
        const b = a.slice(); b[k] = hi[k];
        seg(a, b);
      }
      ctx.stroke();
    }
    // feeds: cut, then still to cut; rapids dashed
    const at = (arr, i) => [[arr[6 * i], arr[6 * i + 1], arr[6 * i + 2]], [arr[6 * i + 3], arr[6 * i + 4], arr[6 * i + 5]]];
    for (const [cut, color] of [[true, COLORS.cut], [false, COLORS.feed]]) {
      ctx.strokeStyle = css(color);
      ctx.beginPath();
      path.segs.forEach((s, k) => { if (s.feed && (k < state.done) === cut) seg(...at(path.feed, s.i)); });
      ctx.stroke();
    }
    ctx.strokeStyle = css(COLORS.rapid);
    ctx.setLineDash([6, 5]);
    ctx.beginPath();
    for (let i = 0; i < path.rapid.length / 6; i++) seg(...at(path.rapid, i));
    ctx.stroke();
    ctx.setLineDash([]);
    if (state.trail.length > 1) {
      ctx.strokeStyle = css(COLORS.cut);
      ctx.lineWidth = 2 * lw;
      ctx.beginPath();
      state.trail.forEach((p, i) => { const q = project(p); if (i) ctx.lineTo(q[0], q[1]); else ctx.moveTo(q[0], q[1]); });
      ctx.stroke();
    }
    if (state.tool) {
      const q = project(state.tool);
      ctx.fillStyle = css(COLORS.tool);
      ctx.beginPath();
      ctx.arc(q[0], q[1], 5 * lw, 0, 2 * Math.PI);
      ctx.fill();
    }
  }
  // at most one drawing per frame however many statuses come
  let queued = false;
  const redraw = () => { if (!queued) { queued = true; requestAnimationFrame(() => { queued = false; draw(); }); } };
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    const f = Math.exp(-e.deltaY * 0.001);
    const mx = e.offsetX * devicePixelRatio - canvas.width / 2, my = e.offsetY * devicePixelRatio - canvas.height / 2;
    pan = [mx - (mx - pan[0]) * f, my - (my - pan[1]) * f];   // the point under the pointer stays put
    zoom *= f;
    redraw();
  }, { passive: false });
  let drag = null;
  canvas.addEventListener('pointerdown', (e) => { drag = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); });
  canvas.addEventListener('pointermove', (e) => {
    if (!drag) return;
    pan = [pan[0] + (e.clientX - drag[0]) * devicePixelRatio, pan[1] + (e.clientY - drag[1]) * devicePixelRatio];
    drag = [e.clientX, e.clientY];
    redraw();
  });
  canvas.addEventListener('pointerup', () => { drag = null; });
  new ResizeObserver(() => { fit(); draw(); }).observe(canvas);
  return {
    kind: '2d',
    setPath() { zoom = 1; pan = [0, 0]; fit(); redraw(); },
    setTool: redraw,
    setDone: redraw,
    setView(name) { viewName = VIEWS[name] ? name : 'iso'; zoom = 1; pan = [0, 0]; fit(); redraw(); },
    view() {
      // the projection as a view matrix: screen right, up, depth as rows
      const [r, u] = AXES2D[viewName];
      const d = [r[1] * u[2] - r[2] * u[1], r[2] * u[0] - r[0] * u[2], r[0] * u[1] - r[1] * u[0]];
      return { name: viewName, matrix: [r[0], u[0], d[0], 0, r[1], u[1], d[1], 0, r[2], u[2], d[2], 0, pan[0], pan[1], 0, 1],
               distance: 1 / zoom, target: pan.slice() };
    },
  };
}
