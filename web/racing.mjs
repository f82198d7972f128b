// Racing roads from a seed, outside arlpcg: the segments `arlpcg generate --game racing
// --policies DIR --aux=λ --seed S [--obstacles N]` writes, rebuilt from the racing Generator's
// ONNX export, the seed, λ and the number of obstacles. Same use as levels.mjs:
//
//   import { RacingGenerator } from "./web/racing.mjs";
//   const generator = await RacingGenerator.load(ort, onnxBytes, sidecarJson);
//   const road = await generator.build({ seed: 7, aux: -1, obstacles: 3 });
//   // road.goal, road.start {position, heading}, road.obstacles, road.segments[i] =
//   // {length, curve, height}, road.samples (the centre line every metre or so)
//
// What it follows (arlpcg's sources): `goal_and_start` and `draw_obstacle`
// (crates/core/src/game/racing/rules.rs), `RacingBuild` (its observation with the plan rays,
// `segment_from_action`, `place`: crates/core/src/game/racing/generator.rs), `Road::push`,
// `first_crossing` and `first_obstacle_hit` (crates/core/src/level/road.rs), `Obstacle::
// plan_distance` and `reaches` (crates/core/src/level/racing.rs), and generate's loop as in
// levels.mjs. Limits: the built-in road (9 m wide) and car ranges, one λ per level.

import { ChaCha8Rng } from "./rng.mjs";
import {
  GeneratorNetwork,
  clamp,
  directionHeading,
  fromUnit,
  headingDirection,
  quantize,
  wrapDegrees,
} from "./levels.mjs";

/** Goals: this far away, within this bearing of the start heading, this high (rules.rs). */
const GOAL_DISTANCE = [220.0, 360.0];
const GOAL_BEARING = 40.0;
const GOAL_HEIGHT = [-12.0, 12.0];
/** The built-in road's width, m (`ROAD_WIDTH`); its crossing arc, self and obstacle clearances. */
const ROAD_WIDTH = 9.0;
const CROSSING_ARC = 4.0 * ROAD_WIDTH;
const MIN_SELF_DISTANCE = ROAD_WIDTH + 3.0;
const MIN_OBSTACLE_DISTANCE = 0.5 * ROAD_WIDTH + 1.5;
/** The road's end completes it this near the goal (`GOAL_REACH_*`). */
const GOAL_REACH_HORIZONTAL = 12.0;
const GOAL_REACH_VERTICAL = 6.0;
/** Centre-line samples about this far apart, m (`SAMPLE_SPACING`). */
const SAMPLE_SPACING = 1.0;
/** The plan rays (`RAYS`, `RAY_SPREAD`, `RAY_LENGTH`, `RAY_STEP`). */
const RAYS = 9;
const RAY_SPREAD = 80.0;
const RAY_LENGTH = 80.0;
const RAY_STEP = 4.0;
/** The level format's segment ranges the observation scales by (`SEGMENT_*`). */
const SEGMENT_LENGTH = [20.0, 30.0];
const SEGMENT_CURVE_MAX = 30.0;
const SEGMENT_HEIGHT_MAX = 5.0;

const RADIANS_PER_DEGREE = Math.PI / 180.0;
const DEGREES_PER_RADIAN = 180.0 / Math.PI;

/** Horizontal distance from (x, z) to an obstacle's footprint (`Obstacle::plan_distance`). */
function planDistance(o, x, z) {
  if (o.kind === "box") {
    const dx = x - o.position[0];
    const dz = z - o.position[2];
    const h = o.heading * RADIANS_PER_DEGREE;
    const s = Math.sin(h);
    const c = Math.cos(h);
    const localX = c * dx - s * dz;
    const localZ = s * dx + c * dz;
    const outX = Math.max(Math.abs(localX) - 0.5 * o.size[0], 0.0);
    const outZ = Math.max(Math.abs(localZ) - 0.5 * o.size[2], 0.0);
    return Math.hypot(outX, outZ);
  }
  return Math.max(Math.hypot(x - o.position[0], z - o.position[2]) - o.radius, 0.0);
}

/** rand's `random_bool(0.5)`: a u64 below 2⁶³. */
function randomHalf(rng) {
  const [hi] = rng.nextU64Halves();
  return hi < 0x80000000;
}

/** An obstacle between the start and the goal, clear of both, or null (`draw_obstacle`). */
function drawObstacle(rng, goal) {
  const along = rng.randomRange(0.25, 0.75);
  const across = rng.randomRange(-25.0, 25.0);
  const length = Math.max(Math.hypot(goal[0], goal[2]), 1.0);
  const ux = goal[0] / length;
  const uz = goal[2] / length;
  const position = [
    quantize(along * goal[0] - across * uz),
    quantize(along * goal[1] - 2.0),
    quantize(along * goal[2] + across * ux),
  ];
  let obstacle;
  if (randomHalf(rng)) {
    const size = [];
    size.push(quantize(rng.randomRange(4.0, 14.0)));
    size.push(quantize(rng.randomRange(3.0, 10.0)));
    size.push(quantize(rng.randomRange(4.0, 14.0)));
    obstacle = { kind: "box", position, size, heading: quantize(rng.randomRange(-180.0, 180.0)) };
  } else {
    const radius = quantize(rng.randomRange(2.0, 7.0));
    obstacle = { kind: "cylinder", position, radius, height: quantize(rng.randomRange(3.0, 10.0)) };
  }
  const clear = MIN_OBSTACLE_DISTANCE + 12.0;
  const farFrom = (p) => planDistance(obstacle, p[0], p[2]) > clear;
  return farFrom([0.0, 0.0, 0.0]) && farFrom(goal) ? obstacle : null;
}

/** The goal, start heading and obstacles of track `seed`, and the stream that continues. */
export function goalAndStart(seed, obstacles = 0) {
  const rng = ChaCha8Rng.seedFromU64(seed);
  const heading = quantize(rng.randomRange(-180.0, 180.0));
  const bearing = heading + rng.randomRange(-GOAL_BEARING, GOAL_BEARING);
  const distance = rng.randomRange(GOAL_DISTANCE[0], GOAL_DISTANCE[1]);
  const [x, z] = headingDirection(bearing);
  const gx = quantize(distance * x);
  const gy = quantize(rng.randomRange(GOAL_HEIGHT[0], GOAL_HEIGHT[1]));
  const goal = [gx, gy, quantize(distance * z)];
  const placed = [];
  for (let i = 0; i < obstacles; i++) {
    const o = drawObstacle(rng, goal);
    if (o) placed.push(o);
  }
  return { goal, heading, obstacles: placed, rng };
}

/** The centre line of a segment at s from its start (`along`): point, heading (rad), slope. */
function along(origin, heading, curvature, rise, length, s) {
  const h = heading + curvature * s;
  let dx;
  let dz;
  if (Math.abs(curvature) < 1e-12) {
    dx = s * Math.cos(heading);
    dz = -s * Math.sin(heading);
  } else {
    dx = (Math.sin(h) - Math.sin(heading)) / curvature;
    dz = (Math.cos(h) - Math.cos(heading)) / curvature;
  }
  const t = s / length;
  const y = rise * t * t * (3.0 - 2.0 * t);
  const slope = (rise * 6.0 * t * (1.0 - t)) / length;
  return [[origin[0] + dx, origin[1] + y, origin[2] + dz], h, slope];
}

/** The built-in road (`RoadShape::default`, crates/core/src/level/racing.rs): 9 m wide, banking 10° per °/m. */
export const ROAD_SHAPE = Object.freeze({ width: ROAD_WIDTH, banking: 10.0 });
/** The steepest banking, degrees, and the blend either side of a join, m (`MAX_BANK_DEGREES`, `BANK_BLEND`). */
const MAX_BANK_DEGREES = 15.0;
const BANK_BLEND = 6.0;

/** A cross-section's unit vector across the road to the left, tilted by its bank (`RoadSample::left`). */
export function leftOf(sample) {
  const s = Math.sin(sample.heading);
  const c = Math.cos(sample.heading);
  const sb = Math.sin(sample.bank);
  const cb = Math.cos(sample.bank);
  return [-s * cb, -sb, -c * cb];
}

/** A point `lateral` m left of a cross-section's centre (`RoadSample::across`), float64. */
export function across(sample, lateral) {
  const l = leftOf(sample);
  return [0, 1, 2].map((k) => sample.centre[k] + lateral * l[k]);
}

/** A cross-section's surface normal (`RoadSample::up`: forward × left, unit length). */
export function upOf(sample) {
  const unit = (v) => {
    const n = Math.hypot(v[0], v[1], v[2]);
    return v.map((x) => x / n);
  };
  const f = unit([Math.cos(sample.heading), sample.slope, -Math.sin(sample.heading)]);
  const l = leftOf(sample);
  return unit([f[1] * l[2] - f[2] * l[1], f[2] * l[0] - f[0] * l[2], f[0] * l[1] - f[1] * l[0]]);
}

/**
 * The road as `Road` keeps it (crates/core/src/level/road.rs): its cross-sections (`samples`:
 * s, segment, centre, heading in radians, slope, bank in radians), where each segment starts
 * and the end's pose. The Generator's checks use the plan; the Solver's world (racing-solver.mjs)
 * the banks and slopes too.
 */
export class Road {
  constructor(position, headingDegrees, shape = ROAD_SHAPE) {
    this.shape = shape;
    this.samples = [];
    this.starts = [0.0];
    this.banks = [];
    this.segments = 0;
    this.endPoint = position.slice();
    this.endHeading = headingDegrees * RADIANS_PER_DEGREE;
  }

  /** The end's point and heading in degrees (`Road::end`). */
  end() {
    return [this.endPoint, this.endHeading * DEGREES_PER_RADIAN];
  }

  get length() {
    return this.starts[this.starts.length - 1];
  }

  /** Appends a segment (`Road::push`); the samples its join's bank blend reaches are re-banked. */
  push(params) {
    const index = this.segments;
    const origin = this.endPoint;
    const heading = this.endHeading;
    const length = params.length;
    const curvature = (params.curve * RADIANS_PER_DEGREE) / length;
    const bank = clamp((this.shape.banking * params.curve) / length, -MAX_BANK_DEGREES, MAX_BANK_DEGREES) * RADIANS_PER_DEGREE;
    this.banks.push(bank);
    const startS = this.starts[this.starts.length - 1];
    this.starts.push(startS + length);
    this.segments++;
    if (index > 0) this.samples.pop();
    const steps = Math.ceil(length / SAMPLE_SPACING);
    for (let k = 0; k <= steps; k++) {
      const s = (length * k) / steps;
      const [centre, h, slope] = along(origin, heading, curvature, params.height, length, s);
      this.samples.push({ s: startS + s, segment: index, centre, heading: h, slope, bank: 0.0 });
    }
    const [end, endHeading] = along(origin, heading, curvature, params.height, length, length);
    this.endPoint = end;
    this.endHeading = endHeading;
    const from = startS - BANK_BLEND;
    for (let i = this.samples.length - 1; i >= 0; i--) {
      if (this.samples[i].s < from) break;
      this.samples[i].bank = this.bankAt(this.samples[i].s);
    }
  }

  /** The segment at distance s along the road, clamped to the first and last (`segment_at`). */
  segmentAt(s) {
    for (let i = 1; i < this.starts.length; i++) if (s < this.starts[i]) return i - 1;
    return Math.max(this.banks.length - 1, 0);
  }

  /** The bank at distance s along the road, radians, blended over a join's 6 m (`bank_at`). */
  bankAt(s) {
    const segment = this.segmentAt(s);
    const own = this.banks[segment];
    const start = this.starts[segment];
    const end = this.starts[segment + 1];
    if (segment > 0 && s - start < BANK_BLEND) {
      const t = (s - start + BANK_BLEND) / (2.0 * BANK_BLEND);
      return this.banks[segment - 1] + t * (own - this.banks[segment - 1]);
    }
    if (segment + 1 < this.banks.length && end - s < BANK_BLEND) {
      const t = (s - end + BANK_BLEND) / (2.0 * BANK_BLEND);
      return own + t * (this.banks[segment + 1] - own);
    }
    return own;
  }

  /**
   * The sample nearest `point` horizontally among `window` either side of `hint` (the whole road
   * without a hint), the first of equal distances (`Road::nearest`).
   */
  nearest(point, hint = null, window = 0) {
    const lo = hint === null ? 0 : Math.max(hint - window, 0);
    const hi = hint === null ? this.samples.length : Math.min(hint + window + 1, this.samples.length);
    let best = lo;
    let bestD = Infinity;
    for (let i = lo; i < hi; i++) {
      const c = this.samples[i].centre;
      const dx = c[0] - point[0];
      const dz = c[2] - point[2];
      const d = dx * dx + dz * dz;
      if (d < bestD) {
        bestD = d;
        best = i;
      }
    }
    return best;
  }

  /** The sample nearest distance s along the road, clamped to its ends (`Road::nearest_along`). */
  nearestAlong(s) {
    let lo = 0;
    let hi = this.samples.length;
    while (lo < hi) {
      const mid = (lo + hi) >> 1;
      if (this.samples[mid].s < s) lo = mid + 1;
      else hi = mid;
    }
    const after = lo;
    if (after === 0) return 0;
    if (after === this.samples.length) return after - 1;
    return s - this.samples[after - 1].s < this.samples[after].s - s ? after - 1 : after;
  }

  /** Whether the samples of segment `from` on come within the clearance of an earlier part. */
  crosses(from) {
    const first = this.samples.findIndex((p) => p.segment >= from);
    if (first < 0) return false;
    const min2 = MIN_SELF_DISTANCE * MIN_SELF_DISTANCE;
    for (let j = first; j < this.samples.length; j++) {
      const later = this.samples[j];
      for (let i = 0; i < j; i++) {
        const earlier = this.samples[i];
        if (later.s - earlier.s <= CROSSING_ARC) break;
        const dx = later.centre[0] - earlier.centre[0];
        const dz = later.centre[2] - earlier.centre[2];
        if (dx * dx + dz * dz < min2) return true;
      }
    }
    return false;
  }

  /** Whether the samples of segment `from` on come within the clearance of an obstacle. */
  hitsObstacle(obstacles, from) {
    return this.samples.some(
      (p) => p.segment >= from && obstacles.some((o) => planDistance(o, p.centre[0], p.centre[2]) < MIN_OBSTACLE_DISTANCE),
    );
  }
}

/** The 9 plan rays from the road's end to the first point `near` says (`RacingBuild::rays`). */
function rays(road, near, out, offset) {
  const [end, heading] = road.end();
  const steps = Math.trunc(RAY_LENGTH / RAY_STEP);
  for (let k = 0; k < RAYS; k++) {
    const angle = heading - RAY_SPREAD + (2.0 * RAY_SPREAD * k) / (RAYS - 1);
    const [dx, dz] = headingDirection(angle);
    let value = 1.0;
    for (let i = 1; i <= steps; i++) {
      const d = i * RAY_STEP;
      if (near(end[0] + d * dx, end[2] + d * dz)) {
        value = d / RAY_LENGTH;
        break;
      }
    }
    out[offset + k] = Math.fround(value);
  }
}

/** The racing Generator's 31 observation columns (`RacingBuild::observe`). */
export function observe(road, segments, goal, obstacles, aux, maxSegments, out) {
  const [end, heading] = road.end();
  const [fx, fz] = headingDirection(heading);
  const d = [goal[0] - end[0], goal[1] - end[1], goal[2] - end[2]];
  const toGoal = [d[0] * fx + d[2] * fz, d[1], d[0] * fz - d[2] * fx];
  const distance = Math.hypot(toGoal[0], toGoal[2]);
  const bearing = Math.atan2(toGoal[2], toGoal[0]);
  const last = segments.length
    ? segments[segments.length - 1]
    : null;
  const lastValues = last
    ? [
        ((last.length - SEGMENT_LENGTH[0]) / (SEGMENT_LENGTH[1] - SEGMENT_LENGTH[0])) * 2.0 - 1.0,
        last.curve / SEGMENT_CURVE_MAX,
        last.height / SEGMENT_HEIGHT_MAX,
      ]
    : [0.0, 0.0, 0.0];
  const h = heading * RADIANS_PER_DEGREE;
  const values = [
    toGoal[0] / 100.0,
    toGoal[1] / 100.0,
    toGoal[2] / 100.0,
    Math.sin(bearing),
    Math.cos(bearing),
    distance / 300.0,
    Math.sin(h),
    Math.cos(h),
    ...lastValues,
    1.0 - segments.length / maxSegments,
  ];
  for (let i = 0; i < values.length; i++) out[i] = Math.fround(values[i]);
  let at = values.length;
  rays(road, (x, z) => obstacles.some((o) => planDistance(o, x, z) < MIN_OBSTACLE_DISTANCE), out, at);
  at += RAYS;
  const reach = road.length - CROSSING_ARC;
  const earlier = [];
  for (let i = 0; i < road.samples.length; i += 3) {
    const p = road.samples[i];
    if (!(p.s < reach)) break;
    earlier.push([p.centre[0], p.centre[2]]);
  }
  const apart2 = MIN_SELF_DISTANCE * MIN_SELF_DISTANCE;
  rays(
    road,
    (x, z) => earlier.some((c) => (c[0] - x) * (c[0] - x) + (c[1] - z) * (c[1] - z) < apart2),
    out,
    at,
  );
  at += RAYS;
  out[at] = Math.fround(aux);
  return at + 1;
}

/** The segment an action row stands for (`segment_from_action`). */
export function segmentFromAction(road, goal, row, rules) {
  const unit = (v) => (Number.isNaN(v) ? 0.0 : clamp(v, -1.0, 1.0));
  const [end, heading] = road.end();
  const length = quantize(fromUnit(unit(row[0]), rules.min_length, rules.max_length));
  const bearing = wrapDegrees(directionHeading(goal[0] - end[0], goal[2] - end[2]) - heading);
  const curve = quantize(clamp(bearing + rules.curve_offset * unit(row[1]), -rules.max_curve, rules.max_curve));
  const plan = Math.max(Math.hypot(goal[0] - end[0], goal[2] - end[2]), 1e-6);
  const onCourse = (goal[1] - end[1]) * Math.min(length / plan, 1.0);
  const height = quantize(clamp(onCourse + rules.max_height * unit(row[2]), -rules.max_height, rules.max_height));
  return { length, curve, height };
}

/** A loaded racing Generator. */
export class RacingGenerator {
  static async load(ort, onnx, sidecar, options = {}) {
    return new RacingGenerator(await GeneratorNetwork.load(ort, onnx, sidecar, "racing", options));
  }

  constructor(network) {
    this.network = network;
  }

  /**
   * The road of `seed` at λ `aux` among `obstacles` drawn obstacles, as `arlpcg generate --game
   * racing` writes it, with `attempt` the attempt that completed it; throws where none does.
   */
  async build({ seed, aux = 0.0, obstacles = 0, knobs = [] }) {
    const net = this.network;
    const rules = net.builtIn;
    const scene = goalAndStart(seed, obstacles);
    const { goal, heading, rng } = scene;
    const observation = new Float32Array(net.observationSize);
    for (let attempt = 0; attempt < net.attempts; attempt++) {
      const road = new Road([0.0, 0.0, 0.0], heading);
      const segments = [];
      while (segments.length < net.maxPieces) {
        const used = observe(road, segments, goal, scene.obstacles, aux, net.maxPieces, observation);
        for (let i = used; i < net.observationSize; i++) observation[i] = Math.fround(knobs[i - used] ?? 0.0);
        const action = await net.choose(observation, rng);
        const index = segments.length;
        const segment = segmentFromAction(road, goal, action, rules);
        road.push(segment);
        segments.push(segment);
        if (road.crosses(index) || road.hitsObstacle(scene.obstacles, index)) break;
        const [end] = road.end();
        const horizontal = Math.hypot(end[0] - goal[0], end[2] - goal[2]);
        if (horizontal <= GOAL_REACH_HORIZONTAL && Math.abs(end[1] - goal[1]) <= GOAL_REACH_VERTICAL) {
          return {
            seed,
            aux,
            goal,
            start: { position: [0.0, 0.0, 0.0], heading },
            obstacles: scene.obstacles,
            attempt,
            segments,
            samples: road.samples,
          };
        }
      }
    }
    throw new Error(`the Generator built no valid road toward goal ${goal} at λ = ${aux} in ${net.attempts} attempts`);
  }
}
