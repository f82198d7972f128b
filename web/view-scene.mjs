// The scene `arlpcg view` draws, for a level built in the page (levels.mjs, racing.mjs): the
// same boxes, road and markers the server's scene has (`scene_json`, src/services/view.rs, over
// crates/core/src/level/scene.rs), without the failure tints and trail of a played level.
//
//   boxes:  { name, centre, heading (degrees), extents, rgba }
//   meshes: { name, positions, normals, indices (flat), rgba }
//   points: { name, position, heading }

import { wrapDegrees } from "./levels.mjs";
import { across, leftOf, upOf } from "./racing.mjs";

/** Each material's colour (`Material::colour`). */
const RGBA = {
  block: [0.55, 0.57, 0.62, 1.0],
  start_block: [0.2, 0.55, 0.25, 1.0],
  goal_block: [0.85, 0.65, 0.1, 1.0],
  start_marker: [0.1, 0.8, 0.2, 1.0],
  goal_marker: [0.95, 0.15, 0.1, 1.0],
  road: [0.18, 0.18, 0.2, 1.0],
  road_edge: [0.45, 0.4, 0.35, 1.0],
  obstacle: [0.6, 0.3, 0.2, 1.0],
};
/** A platform block's thickness under its top, m (`BLOCK_THICKNESS`). */
const BLOCK_THICKNESS = 1.0;
/** How far a road's skirts hang below its edges, m (`SKIRT_DEPTH`). */
const SKIRT_DEPTH = 0.8;
/** Sides of a cylinder obstacle's mesh (`CYLINDER_SIDES`). */
const CYLINDER_SIDES = 24;
/** The finish region (`finish_zone`): over a platform goal block's top, m; along a road's last metres, below and above its centre line, m. */
const PLATFORM_FINISH_HEIGHT = 2.0;
const RACING_FINISH_LENGTH = 3.0;
const RACING_FINISH_BELOW = 2.0;
const RACING_FINISH_ABOVE = 4.0;

/** A post over `base` (`marker`): seen, not collided with. */
function marker(name, base, height, material) {
  return { name, centre: [base[0], base[1] + 0.5 * height, base[2]], heading: 0.0, extents: [0.3, height, 0.3], rgba: RGBA[material] };
}

function scene(game, title, pieces, boxes, meshes, points, why) {
  return { title, game, pieces, boxes, meshes, points, trail: { none: why } };
}

/**
 * The scene of a platform level as `PlatformGenerator.build` returns it.
 * @param {object} level `{ goal, start: {position, heading, size}, blocks: [{size, position, heading}] }`
 */
export function platformScene(level, title, why) {
  const block = (name, p, material) => ({
    name,
    centre: [p.position[0], p.position[1] - 0.5 * BLOCK_THICKNESS, p.position[2]],
    heading: p.heading,
    extents: [p.size, BLOCK_THICKNESS, p.size],
    rgba: RGBA[material],
  });
  const start = { ...level.start, heading: wrapDegrees(level.start.heading) };
  const last = level.blocks.length - 1;
  const boxes = [block("start_block", start, "start_block")];
  level.blocks.forEach((b, i) => boxes.push(block(`block_${String(i).padStart(3, "0")}`, b, i === last ? "goal_block" : "block")));
  boxes.push(marker("start", start.position, 2.0, "start_marker"), marker("goal", level.goal, 3.0, "goal_marker"));
  const goal = level.blocks[last];
  const h = PLATFORM_FINISH_HEIGHT;
  const points = [
    { name: "spawn", position: start.position, heading: start.heading },
    { name: "finish", position: goal.position, heading: goal.heading },
    {
      name: "finish_zone",
      position: [goal.position[0], goal.position[1] + 0.5 * h, goal.position[2]],
      heading: goal.heading,
      size: [goal.size, h, goal.size],
    },
  ];
  return scene("platform", title, level.blocks.length, boxes, [], points, why);
}

/** Two vertices per cross-section from `first` to `last` and the strip between them (`TriangleMesh::strip`). */
function strip(samples, vertex, a, b) {
  const positions = [], normals = [], indices = [];
  samples.forEach((p, row) => {
    for (const [position, normal] of vertex(p)) {
      positions.push(...position.map(Math.fround));
      normals.push(...normal.map(Math.fround));
    }
    if (row > 0) {
      const here = 2 * (row - 1), next = here + 2;
      indices.push(here + a, here + b, next + b, here + a, next + b, next + a);
    }
  });
  return { positions, normals, indices };
}

/** Both skirts of a stretch of road (`skirts_between`): left, then right, each facing out. */
function skirts(samples, width) {
  const parts = [1.0, -1.0].map((side) =>
    strip(
      samples,
      (p) => {
        const outward = leftOf(p).map((c) => side * c);
        const top = across(p, side * 0.5 * width);
        return [[top, outward], [[top[0], top[1] - SKIRT_DEPTH, top[2]], outward]];
      },
      side > 0 ? 1 : 0,
      side > 0 ? 0 : 1,
    ),
  );
  const base = parts[0].positions.length / 3;
  return {
    positions: [...parts[0].positions, ...parts[1].positions],
    normals: [...parts[0].normals, ...parts[1].normals],
    indices: [...parts[0].indices, ...parts[1].indices.map((i) => i + base)],
  };
}

/** An upright cylinder standing on `base` (`cylinder`): side, then top and bottom fans. */
function cylinder(base, radius, height) {
  const positions = [], normals = [], indices = [];
  const vertex = (p, n) => { positions.push(...p.map(Math.fround)); normals.push(...n); };
  const angle = (k) => (2 * Math.PI * k) / CYLINDER_SIDES;
  for (let k = 0; k <= CYLINDER_SIDES; k++) {
    const [s, c] = [Math.sin(angle(k)), Math.cos(angle(k))];
    const x = base[0] + radius * c, z = base[2] - radius * s;
    vertex([x, base[1], z], [c, 0, -s]);
    vertex([x, base[1] + height, z], [c, 0, -s]);
  }
  for (let row = 0; row < CYLINDER_SIDES; row++) {
    const here = 2 * row, next = here + 2;
    indices.push(here + 1, here, next, here + 1, next, next + 1);
  }
  for (const [y, up] of [[base[1] + height, 1.0], [base[1], -1.0]]) {
    const centre = positions.length / 3;
    vertex([base[0], y, base[2]], [0, up, 0]);
    for (let k = 0; k < CYLINDER_SIDES; k++) vertex([base[0] + radius * Math.cos(angle(k)), y, base[2] - radius * Math.sin(angle(k))], [0, up, 0]);
    for (let k = 0; k < CYLINDER_SIDES; k++) {
      const a = centre + 1 + k, b = centre + 1 + ((k + 1) % CYLINDER_SIDES);
      indices.push(...(up > 0 ? [centre, a, b] : [centre, b, a]));
    }
  }
  return { positions, normals, indices };
}

/**
 * The scene of a racing level as `RacingGenerator.build` returns it.
 * @param {object} level `{ goal, start: {position, heading}, obstacles, segments, samples }`
 * @param {number} width the road's width, m
 */
export function racingScene(level, title, why, width) {
  const boxes = [marker("start", level.start.position, 2.0, "start_marker"), marker("goal", level.goal, 3.0, "goal_marker")];
  const meshes = [];
  level.segments.forEach((_, i) => {
    // `segment_samples`: the cross-sections of segment i and the first of the next.
    const first = level.samples.findIndex((p) => p.segment >= i);
    const after = level.samples.findIndex((p) => p.segment > i);
    const samples = level.samples.slice(first, after < 0 ? level.samples.length : after + 1);
    const name = `segment_${String(i).padStart(3, "0")}`;
    const surface = strip(samples, (p) => [[across(p, 0.5 * width), upOf(p)], [across(p, -0.5 * width), upOf(p)]], 0, 1);
    meshes.push({ name, ...surface, rgba: RGBA.road }, { name, ...skirts(samples, width), rgba: RGBA.road_edge });
  });
  level.obstacles.forEach((o, i) => {
    const name = `obstacle_${String(i).padStart(3, "0")}`;
    if (o.kind === "box") {
      boxes.push({ name, centre: [o.position[0], o.position[1] + 0.5 * o.size[1], o.position[2]], heading: o.heading, extents: o.size, rgba: RGBA.obstacle });
    } else {
      meshes.push({ name, ...cylinder(o.position, o.radius, o.height), rgba: RGBA.obstacle });
    }
  });
  const end = level.samples[level.samples.length - 1];
  // The road's last metres, back from its end along its heading and slope.
  const along = [Math.cos(end.heading), end.slope, -Math.sin(end.heading)];
  const norm = Math.hypot(...along);
  const centre = [0, 1, 2].map((k) => end.centre[k] - (0.5 * RACING_FINISH_LENGTH * along[k]) / norm);
  const height = RACING_FINISH_BELOW + RACING_FINISH_ABOVE;
  const points = [
    { name: "spawn", position: level.start.position, heading: level.start.heading },
    { name: "finish", position: end.centre, heading: (end.heading * 180) / Math.PI },
    {
      name: "finish_zone",
      position: [centre[0], centre[1] + 0.5 * height - RACING_FINISH_BELOW, centre[2]],
      heading: (end.heading * 180) / Math.PI,
      size: [width, height, RACING_FINISH_LENGTH],
    },
  ];
  return scene("racing", title, level.segments.length, boxes, meshes, points, why);
}
