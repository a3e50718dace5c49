// Where the running program is along its drawing. The NCK's status gives
// the line in motion and the position, but neither the end of the move nor
// which of the program's segments are done, and the canonical text has no
// line numbers: so the tool is followed along the segments in the order the
// program runs them (canon.js's segs), only ever forward from the last match.
// A forward-only search is what keeps a pocket's rings apart where they cross
// or pass close to each other. From that: the distance to go (the end of the
// move the tool is on, minus the tool) and how many segments are cut.

const WINDOW = 400;     // segments looked at ahead of the last match per status
const ON_PATH = 0.5;    // mm: farther from every segment, the tool is off the path
                        // (a tool change, a jog in a pause): no distance to go
// Until the tool is first found on the path after a reset (a run from a
// line far into the program starts beyond any window), the search covers
// this many segments, at every FIRST_EVERY-th status: a long CAM program's
// whole path 50 times a second would take the page's time.
const FIRST_SPAN = 200000;
const FIRST_EVERY = 10;

function distToSeg(p, a, b) {
  const d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
  const l2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  let t = l2 > 0 ? ((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1] + (p[2] - a[2]) * d[2]) / l2 : 0;
  t = Math.max(0, Math.min(1, t));
  return Math.hypot(a[0] + t * d[0] - p[0], a[1] + t * d[1] - p[1], a[2] + t * d[2] - p[2]);
}

export function createProgress() {
  let path = null, at = 0, onPath = false, found = false, tries = 0;
  const ends = (s) => {
    const arr = s.feed ? path.feed : path.rapid, k = 6 * s.i;
    return [[arr[k], arr[k + 1], arr[k + 2]], [arr[k + 3], arr[k + 4], arr[k + 5]]];
  };
  return {
    // a new program, or a new run of it: back to its start
    reset(p) { if (p !== undefined) path = p; at = 0; onPath = false; found = false; tries = 0; },
    // the tool's point (canon.js's toolPoint) while the program runs
    follow(xyz) {
      if (!path || !path.segs.length) return;
      const wide = !found && tries++ % FIRST_EVERY === 0;
      const n = Math.min(path.segs.length, at + (wide ? FIRST_SPAN : WINDOW));
      let best = Infinity, bestAt = at;
      for (let i = at; i < n; i++) {
        const [a, b] = ends(path.segs[i]);
        const d = distToSeg(xyz, a, b);
        // the earliest of equally near segments: a segment's end is also the
        // next one's start, and the tool is on the one it has not finished
        if (d < best - 1e-4) { best = d; bestAt = i; }
      }
      onPath = best <= ON_PATH;
      if (onPath) { at = bestAt; found = true; }
    },
    // per axis x, y, z: the end of the move the tool is on minus the tool;
    // null while the tool is not on the program's path
    toGo(xyz) {
      if (!path || !onPath || !path.segs.length) return null;
      const end = path.moveEnd[path.segs[at].move];
      return [end[0] - xyz[0], end[1] - xyz[1], end[2] - xyz[2]];
    },
    // segments before this one (in the program's order) are cut
    get done() { return at; },
  };
}
