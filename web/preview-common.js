// What both previews (three.js and 2D) draw alike: colours, the views'
// directions and the travel box.

export const COLORS = {
  bg: 0x0b0d10, feed: 0x4fb3ff, rapid: 0xe0a040, cut: 0x5cff8a, tool: 0xff4060,
  box: 0x8a7fd0, travel: 0x4a5563, grid: 0x1c232b, gridMajor: 0x2c3a48,
};
export const css = (c) => '#' + c.toString(16).padStart(6, '0');

// Where the camera stands, seen from what it looks at (work X, Y, Z): top
// looks down Z, front along +Y (from the operator's side), side along -X
// (from the right), iso from the front left above, as LinuxCNC's AXIS.
export const VIEWS = {
  top: [0, 0, 1],
  front: [0, -1, 0],
  side: [1, 0, 0],
  iso: [-0.5, -1.1, 0.9],
};

// The machine's box: its travel when the panel knows it (soft limits in
// work coordinates), else the program's own extents.
export function travelBox(path, travel) {
  if (travel) return travel;
  return extentsBox(path);
}

// The program's extents, [min, max] (null: nothing to draw).
export function extentsBox(path) {
  if (!path || !isFinite(path.min[0])) return null;
  return [path.min.slice(), path.max.slice()];
}

// What the view fits: the program, so that a part small beside the travel
// is drawn large enough to read; the travel alone before a program loads.
export function fitBox(path, travel) {
  return extentsBox(path) || travel || null;
}
