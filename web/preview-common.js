// What both previews (three.js and 2D) draw alike: colours, the views'
// directions and the travel box.

export const COLORS = {
  bg: 0x0b0d10, feed: 0x4fb3ff, rapid: 0xe0a040, cut: 0x5cff8a, tool: 0xff4060,
  box: 0x8a7fd0, grid: 0x1c232b, gridMajor: 0x2c3a48,
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

// The box the preview draws: the machine's travel when the panel knows it
// (soft limits in work coordinates), else the program's own extents.
export function travelBox(path, travel) {
  if (travel) return travel;
  if (!path || !isFinite(path.min[0])) return null;
  return [path.min.slice(), path.max.slice()];
}
