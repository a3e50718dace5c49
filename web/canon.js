// The interpreter's canonical commands (`cnc-run parse --canon`, the text the
// NCK runs) as line segments for the preview: feeds and arcs, rapids apart.
// Coordinates are the program's work coordinates in mm (inch programs scaled).
// Only the linear axes are drawn; rotary words are ignored. tlo says the tool
// length offset the program uses with each tool, so that the machine's
// position can be put on the drawing. The canonical text carries no line
// numbers, so order is what ties the drawing to the machine: segs lists every
// segment in the order the program runs them (kind, index into its array,
// the move it belongs to), and moveEnd where each move ends; an arc is one
// move of many chords. progress.js follows the tool along them.

const ARC_SEG_DEG = 5;   // one chord per 5 degrees: smooth at any zoom the panel offers

function nums(line) {
  const open = line.indexOf('('), close = line.lastIndexOf(')');
  return line.slice(open + 1, close).split(/[ ,]+/).map((t) => parseFloat(t));
}

export function parseCanon(text) {
  const feed = [], rapid = [];
  let pos = null;            // unknown until the first move
  let plane = 'XY', scale = 1, tool = 0;
  const tlo = {};
  const min = [Infinity, Infinity, Infinity], max = [-Infinity, -Infinity, -Infinity];
  const errors = [];
  const segs = [], moveEnd = [];
  const push = (arr, a, b) => {
    segs.push({ feed: arr === feed, i: arr.length / 6, move: moveEnd.length });
    arr.push(a[0], a[1], a[2], b[0], b[1], b[2]);
    for (const p of [a, b]) for (let i = 0; i < 3; i++) { min[i] = Math.min(min[i], p[i]); max[i] = Math.max(max[i], p[i]); }
  };
  for (const line of text.split('\n')) {
    if (line.includes(': error:')) { errors.push(line); continue; }
    const name = line.slice(0, line.indexOf('('));
    if (name === 'USE_LENGTH_UNITS') scale = line.includes('INCHES') ? 25.4 : line.includes('CM') ? 10 : 1;
    else if (name === 'CHANGE_TOOL') tool = nums(line)[0];
    else if (name === 'USE_TOOL_LENGTH_OFFSET') {
      const v = nums(line).slice(0, 3).map((x) => x * scale);
      if (v.some((x) => x !== 0) || !tlo[tool]) tlo[tool] = v;   // not the reset at the end
    } else if (name === 'SELECT_PLANE') plane = line.includes('_YZ') ? 'YZ' : line.includes('_XZ') ? 'XZ' : 'XY';
    else if (name === 'STRAIGHT_TRAVERSE' || name === 'STRAIGHT_FEED' || name === 'STRAIGHT_PROBE') {
      const v = nums(line).slice(0, 3).map((x) => x * scale);
      if (pos) { push(name === 'STRAIGHT_TRAVERSE' ? rapid : feed, pos, v); moveEnd.push(v); }
      pos = v;
    } else if (name === 'ARC_FEED' && pos) {
      pos = arc(nums(line).map((x, i) => (i === 4 ? x : x * scale)), plane, pos, (a, b) => push(feed, a, b));
      moveEnd.push(pos);
    }
  }
  return { feed, rapid, min, max, errors, tlo, segs, moveEnd };
}

// The machine's work position (per axis, in the status's order) as a point
// of the drawing: the program's tool length offset of toolNo taken off, so
// that the tool's tip meets the path it cuts.
export function toolPoint(path, p, axes, toolNo) {
  const tlo = (path && path.tlo[toolNo]) || [0, 0, 0];
  return [0, 1, 2].map((i) => (axes[i] ? p[i] - tlo[i] : 0));
}

// rs274's ARC_FEED(first_end, second_end, first_axis, second_axis, rotation,
// axis_end_point, ...): first/second are X/Y in XY, Z/X in XZ, Y/Z in YZ.
function arc(v, plane, start, seg) {
  const [fe, se, fc, sc, rot, ae] = v;
  const idx = plane === 'XY' ? [0, 1, 2] : plane === 'XZ' ? [2, 0, 1] : [1, 2, 0];
  const s1 = start[idx[0]], s2 = start[idx[1]], s3 = start[idx[2]];
  const r = Math.hypot(s1 - fc, s2 - sc);
  const a0 = Math.atan2(s2 - sc, s1 - fc);
  let a1 = Math.atan2(se - sc, fe - fc);
  const turns = Math.max(1, Math.abs(rot)) - 1;
  if (rot > 0) { while (a1 <= a0 + 1e-9) a1 += 2 * Math.PI; a1 += 2 * Math.PI * turns; }
  else { while (a1 >= a0 - 1e-9) a1 -= 2 * Math.PI; a1 -= 2 * Math.PI * turns; }
  const n = Math.max(2, Math.ceil(Math.abs(a1 - a0) / (ARC_SEG_DEG * Math.PI / 180)));
  let prev = start;
  for (let i = 1; i <= n; i++) {
    const t = i / n, a = a0 + (a1 - a0) * t;
    const p = [0, 0, 0];
    p[idx[0]] = i === n ? fe : fc + r * Math.cos(a);
    p[idx[1]] = i === n ? se : sc + r * Math.sin(a);
    p[idx[2]] = s3 + (ae - s3) * t;
    seg(prev, p);
    prev = p;
  }
  return prev;
}
