// The racing Solver outside arlpcg: an exported Solver (`arlpcg export-policy
// policies/racing/solver.safetensors --out S.onnx`: S.onnx and its sidecar S.onnx.json) driving
// a racing level in rapier's JavaScript build, as `arlpcg verify` drives it in rapier3d.
// An ES module with no build step and no dependency of its own: the caller hands it an
// onnxruntime module (onnxruntime-node, or onnxruntime-web in a page) and an initialized rapier
// module (`@dimforge/rapier3d-compat`, after `await RAPIER.init()`).
//
//   import * as ort from "onnxruntime-node";
//   import RAPIER from "@dimforge/rapier3d-compat";
//   import { RacingSolver, RacingCourse, parseRacingLevel } from "./web/racing-solver.mjs";
//   await RAPIER.init();
//   const solver = await RacingSolver.load(ort, onnxBytes, sidecarJson);
//   const course = new RacingCourse(RAPIER, parseRacingLevel(levelYamlText));
//   const results = await solver.play(course, { trials: 20, seed: 0 });
//   // results[i] = { seed, outcome: "Success" | "OffRoad" | "Flipped" | "TimedOut", steps,
//   //                progress, segment, airSteps }
//
// What it reproduces (the Rust it follows, in arlpcg's sources):
// - the road (`Road`, crates/core/src/level/road.rs; its cross-sections by `Road` in racing.mjs):
//   one triangle mesh, two vertices per cross-section at ±width/2 along the banked `left`
//   (`surface_mesh`), in float32, with parry's FIX_INTERNAL_EDGES, friction 1; the obstacles as
//   boxes (turned by their heading) and cylinders standing on their `position`
//   (`TrackShapes::new`, crates/core/src/game/racing/car.rs);
// - the car (`RacingWorld`, car.rs): a dynamic box chassis (half extents 2 × 0.3 × 0.9 m, mass
//   1200 kg with its centre 0.25 m below the box's, the box's inertia, friction 0.6, linear
//   damping 0.21 /s, angular 0.5, never asleep) on rapier's ray-cast vehicle controller, four
//   wheels with the game's tuning, the engine on the rear wheels, steering on the front, brakes
//   on all; one physics step of 1/30 s per decision (`RacingWorld::step`), with the game's
//   contact-pair hook (`RoadContacts`: the chassis and the road left out of collision detection
//   while `chassis_clear` holds) and CCD only where the chassis may meet the road or an
//   obstacle (`max_ccd_substeps` 1, else 0);
// - the reset (`reset_on`, crates/core/src/game/racing/env.rs; docs/engines.md, "A reset, from
//   `spawn`"), drawn from the run's ChaCha8 stream as rand draws it;
// - the observation (`observe`, env.rs; docs/engines.md, the racing row of "Porting a policy" and
//   "Racing, the road's cross-sections"): goal, bearing, velocity, spin, up, lateral offset,
//   road bearing, the centre line ahead and the 20-ray fan;
// - the run's end (`SolverEnv::step` for RacingEnv, env.rs): success within 3 m of the road's
//   end and on the road; off the road (0.3 s with no wheel touching beyond an edge, or 4 m below
//   the road); flipped (1 s with the up axis below 0.3); the time limit (10 s + the road's
//   length at 6 m/s);
// - the actions as `verify` draws them (solver.mjs: mean + std·n per column, throttle then
//   steer; `CarAction::from_policy_row` clips them to [-1, 1]).
//
// The arithmetic is the game's float32 (Math.fround where Rust rounds) and float64 where the
// game's is (the road, the along-track bookkeeping). What differs from the Rust game is only
// what rapier's JS build and onnxruntime compute: see docs/engines.md, "Playing a Solver in
// rapier.js".

import { ChaCha8Rng } from "./rng.mjs";
import { Road, ROAD_SHAPE, across } from "./racing.mjs";
import { readLevelYaml } from "./level-file.mjs";
import {
  GameSolver,
  SolverNetwork,
  add,
  clipAction,
  conjugate,
  dot,
  f32,
  length,
  rotate,
  rotationY,
  scale,
  sub,
} from "./solver.mjs";

/** The built-in car (`CarProfile::default`, crates/core/src/level/profile/abilities.rs). */
export const BUILT_IN_CAR = Object.freeze({
  engine_force: 7200.0,
  mass: 1200.0,
  grip: 0.9,
  max_steer: 0.5,
  damping: 0.21,
});

// car.rs
/** Seconds per decision, one physics step (`DECISION_DT`); gravity, m/s². */
const DECISION_DT = f32(1.0 / 30.0);
const GRAVITY = f32(9.81);
/** Half extents of the chassis box (length, height, width), m; its centre of mass this far below. */
const CHASSIS_HALF = [2.0, 0.3, 0.9].map(f32);
const COM_DROP = f32(0.25);
/** Wheel attachment points, chassis frame: front left, front right, rear left, rear right. */
const WHEELS = [
  [1.3, -0.2, -0.85],
  [1.3, -0.2, 0.85],
  [-1.3, -0.2, -0.85],
  [-1.3, -0.2, 0.85],
].map((w) => w.map(f32));
const WHEEL_RADIUS = f32(0.35);
const SUSPENSION_REST = f32(0.35);
/** The wheels' tuning (`WheelTuning` in `RacingWorld::new`; friction_slip is the car's grip). */
const SUSPENSION_STIFFNESS = 30.0;
const SUSPENSION_COMPRESSION = 3.0;
const SUSPENSION_DAMPING = 4.0;
const MAX_SUSPENSION_TRAVEL = 0.3;
const SIDE_FRICTION_STIFFNESS = 1.0;
/** The car starts this far along the road, m, and this high above its ride height. */
const START_S = 5.0;
const START_LIFT = f32(0.25);
/** `chassis_clear`'s constants (car.rs), in float32 as Rust evaluates them. */
const BOTTOM_BELOW_WHEELS = f32(CHASSIS_HALF[1] + WHEELS[0][1]);
const CORNER_SPREAD = f32(
  f32(f32(CHASSIS_HALF[0] - WHEELS[0][0]) / f32(2.0 * WHEELS[0][0])) +
    f32(f32(CHASSIS_HALF[2] - WHEELS[1][2]) / f32(2.0 * WHEELS[1][2])),
);
const CORNER_LEVER = f32(0.71);
const CLEARANCE_SLACK = f32(0.15);
/** Obstacles' plans are widened by this much (`PlanGrid::MARGIN`), m. */
const PLAN_MARGIN = f32(0.01);

// env.rs
const LOOK_AHEAD = [8.0, 16.0, 26.0, 40.0, 60.0];
const FAN_FORWARD = [5.0, 11.0, 19.0, 30.0];
const FAN_LEFT = [-7.0, -3.5, 0.0, 3.5, 7.0];
const FAN_START_HEIGHT = 6.0;
const FAN_LENGTH = 18.0;
const AIR_HEIGHT = f32(1.4);
const OFF_ROAD_S = f32(0.3);
const BELOW_ROAD = 4.0;
const FLIP_UP = f32(0.3);
const FLIP_S = 1.0;
const TIME_BASE_S = 10.0;
const TIME_SPEED = 6.0;
const START_JITTER_M = 1.0;
const START_JITTER_DEG = 4.0;
/** The road's last metres that count as its end (`FINISH_LENGTH`, crates/core/src/level/racing.rs). */
const FINISH_LENGTH = 3.0;
/** The observation's length (`OBSERVATION_SIZE`): 27 state columns and the 20 fan rays. */
export const RACING_SOLVER_OBSERVATION_SIZE = 47;
const FAN_SIZE = FAN_FORWARD.length * FAN_LEFT.length;
const STATE_SIZE = RACING_SOLVER_OBSERVATION_SIZE - FAN_SIZE;

const PI_F32 = f32(Math.PI);
const TAU_F32 = f32(2.0 * Math.PI);
/** `wrap` (env.rs): an f32 angle into [-π, π) by rem_euclid. */
function wrap(angle) {
  const a = f32(angle + PI_F32);
  let r = a % TAU_F32; // fmod of two floats is exact
  if (r < 0.0) r = f32(r + TAU_F32);
  return f32(r - PI_F32);
}

// ---------------------------------------------------------------------------------------------
// Levels.

/**
 * The fields of an arlpcg racing level file that a run needs: `start` (position, heading),
 * `goal` (the road's end when the file gives none), `segments`, `obstacles` and `road` (width,
 * banking; the built-in road when absent). Reads the YAML arlpcg writes (`readLevelYaml`,
 * level-file.mjs; pass a parsed object to `racingLevel` otherwise).
 * @param {string} text
 */
export function parseRacingLevel(text) {
  const doc = readLevelYaml(text);
  if (doc?.game !== undefined && doc.game !== "racing") throw new Error(`not a racing level: game ${doc.game}`);
  return racingLevel(doc);
}

/** A level object (parsed from a level file, YAML or JSON) checked and reduced to what a run needs. */
export function racingLevel(doc) {
  const need = (v, what) => {
    if (v === undefined || v === null) throw new Error(`level: missing ${what}`);
    return v;
  };
  const start = need(doc.start, "start");
  const level = {
    start: { position: need(start.position, "start.position").map(Number), heading: Number(need(start.heading, "start.heading")) },
    goal: doc.goal ? doc.goal.map(Number) : null,
    segments: need(doc.segments, "segments").map((s, i) => ({
      length: Number(need(s.length, `segments[${i}].length`)),
      curve: Number(need(s.curve, `segments[${i}].curve`)),
      height: Number(need(s.height, `segments[${i}].height`)),
    })),
    obstacles: (doc.obstacles ?? []).map((o, i) =>
      o.kind === "box"
        ? { kind: "box", position: o.position.map(Number), size: o.size.map(Number), heading: Number(o.heading ?? 0) }
        : o.kind === "cylinder"
          ? { kind: "cylinder", position: o.position.map(Number), radius: Number(o.radius), height: Number(o.height) }
          : (() => {
              throw new Error(`level: obstacles[${i}] of unknown kind ${o.kind}`);
            })(),
    ),
    road: doc.road ? { width: Number(doc.road.width), banking: Number(doc.road.banking) } : ROAD_SHAPE,
  };
  // No goal written: the road's end (`racing_track`, crates/core/src/level/yaml/file.rs).
  if (!level.goal) level.goal = buildRoad(level).end()[0].slice();
  return level;
}

/** The level's road (`RacingTrack::road`). */
export function buildRoad(level) {
  const road = new Road(level.start.position, level.start.heading, level.road);
  for (const s of level.segments) road.push(s);
  return road;
}

// ---------------------------------------------------------------------------------------------
// The world and the car.

/**
 * A level's road and obstacles, and the runs played on it: each run has a rapier.js world of
 * its own, built at its reset as the Rust game builds one per run (`RacingWorld::new`), so runs
 * side by side do not meet. A run's world is freed when it ends in `play` (`release`); call
 * `release(run)` for runs you drive yourself. rapier.js's memory is WebAssembly's, not the
 * garbage collector's.
 */
export class RacingCourse {
  /**
   * @param {object} RAPIER the rapier3d-compat module, initialized
   * @param {object} level from parseRacingLevel or racingLevel
   * @param {object} [car] a profile's `car:` abilities (default: the built-in car)
   */
  constructor(RAPIER, level, car = BUILT_IN_CAR) {
    this.RAPIER = RAPIER;
    this.level = level;
    this.road = buildRoad(level);
    this.width = level.road.width;
    this.goal = level.goal.slice();
    this.car = {
      engineForce: f32(car.engine_force),
      mass: f32(car.mass),
      grip: f32(car.grip),
      maxSteer: f32(car.max_steer),
      damping: f32(car.damping),
    };
    // Car::brake_impulse: mass · 0.8 g · dt / 4, in f32 from the left.
    this.car.brakeImpulse = f32(f32(f32(f32(this.car.mass * f32(0.8)) * GRAVITY) * DECISION_DT) / 4.0);
    // RacingEnv::time_limit.
    this.maxSteps = Math.ceil((TIME_BASE_S + this.road.length / TIME_SPEED) / DECISION_DT);
    // Road::surface_mesh: two vertices per cross-section (left edge, right edge), f32.
    const samples = this.road.samples;
    this.vertices = new Float32Array(6 * samples.length);
    samples.forEach((p, i) => {
      this.vertices.set(across(p, 0.5 * this.width), 6 * i);
      this.vertices.set(across(p, -0.5 * this.width), 6 * i + 3);
    });
    // TriangleMesh::strip(0, rows, 0, 1): [this, this + 1, next + 1], [this, next + 1, next].
    this.indices = new Uint32Array(6 * (samples.length - 1));
    for (let row = 0; row < samples.length - 1; row++) {
      const t = 2 * row;
      this.indices.set([t, t + 1, t + 3, t, t + 3, t + 2], 6 * row);
    }
    // TrackShapes::new: each obstacle's pose and shape, and its plan's bounding box widened.
    this.obstacles = level.obstacles.map((o) => {
      if (o.kind === "box") {
        const half = o.size.map((v) => f32(0.5 * v));
        const q = rotationY(f32(o.heading * (Math.PI / 180.0)));
        const centre = [f32(o.position[0]), f32(o.position[1] + 0.5 * o.size[1]), f32(o.position[2])];
        // The box's AABB: its half extents through |R| (parry's Cuboid::aabb).
        const ex = f32(f32(Math.abs(rotate(q, [1, 0, 0])[0]) * half[0]) + f32(Math.abs(rotate(q, [0, 0, 1])[0]) * half[2]));
        const ez = f32(f32(Math.abs(rotate(q, [1, 0, 0])[2]) * half[0]) + f32(Math.abs(rotate(q, [0, 0, 1])[2]) * half[2]));
        return { kind: "box", centre, rotation: q, half, plan: planBox(centre, ex, ez) };
      }
      const halfHeight = f32(0.5 * o.height);
      const radius = f32(o.radius);
      const centre = [f32(o.position[0]), f32(o.position[1] + 0.5 * o.height), f32(o.position[2])];
      return { kind: "cylinder", centre, halfHeight, radius, plan: planBox(centre, radius, radius) };
    });
    this.ray = new RAPIER.Ray({ x: 0, y: 0, z: 0 }, { x: 0.0, y: -1.0, z: 0.0 });
  }

  /** Nothing held: each run's world is its own (`release`). */
  free() {}

  /** A world with the car standing at `position` (its wheels' height), heading `heading` rad, at rest (`RacingWorld::new`). */
  world(position, heading) {
    const R = this.RAPIER;
    const car = this.car;
    const world = new R.World({ x: 0.0, y: -GRAVITY, z: 0.0 });
    // The road first, then the obstacles, then the chassis: the handles' order is the Rust's.
    const road = world.createCollider(R.ColliderDesc.trimesh(this.vertices, this.indices, R.TriMeshFlags.FIX_INTERNAL_EDGES).setFriction(1.0));
    for (const o of this.obstacles) {
      const desc = o.kind === "box" ? R.ColliderDesc.cuboid(...o.half) : R.ColliderDesc.cylinder(o.halfHeight, o.radius);
      desc.setTranslation(...o.centre);
      if (o.rotation) desc.setRotation({ x: o.rotation[0], y: o.rotation[1], z: o.rotation[2], w: o.rotation[3] });
      world.createCollider(desc);
    }
    const ride = f32(f32(f32(SUSPENSION_REST + WHEEL_RADIUS) + f32(0.2)) + START_LIFT);
    const q = rotationY(heading);
    const chassis = world.createRigidBody(
      R.RigidBodyDesc.dynamic()
        .setTranslation(position[0], f32(position[1] + ride), position[2])
        .setRotation({ x: q[0], y: q[1], z: q[2], w: q[3] })
        .setLinearDamping(car.damping)
        .setAngularDamping(0.5)
        .setCanSleep(false),
    );
    const [hx, hy, hz] = CHASSIS_HALF;
    const third = f32(car.mass / 3.0);
    const inertia = {
      x: f32(third * f32(f32(hy * hy) + f32(hz * hz))),
      y: f32(third * f32(f32(hx * hx) + f32(hz * hz))),
      z: f32(third * f32(f32(hx * hx) + f32(hy * hy))),
    };
    world.createCollider(
      R.ColliderDesc.cuboid(hx, hy, hz)
        .setMassProperties(car.mass, { x: 0.0, y: -COM_DROP, z: 0.0 }, inertia, { x: 0, y: 0, z: 0, w: 1 })
        .setFriction(0.6)
        .setActiveHooks(R.ActiveHooks.FILTER_CONTACT_PAIRS),
      chassis,
    );
    const vehicle = world.createVehicleController(chassis);
    const maxForce = f32(f32(car.mass * GRAVITY) * 2.0);
    WHEELS.forEach(([x, y, z], i) => {
      vehicle.addWheel({ x, y, z }, { x: 0.0, y: -1.0, z: 0.0 }, { x: 0.0, y: 0.0, z: 1.0 }, SUSPENSION_REST, WHEEL_RADIUS);
      vehicle.setWheelSuspensionStiffness(i, SUSPENSION_STIFFNESS);
      vehicle.setWheelSuspensionCompression(i, SUSPENSION_COMPRESSION);
      vehicle.setWheelSuspensionRelaxation(i, SUSPENSION_DAMPING);
      vehicle.setWheelMaxSuspensionTravel(i, MAX_SUSPENSION_TRAVEL);
      vehicle.setWheelSideFrictionStiffness(i, SIDE_FRICTION_STIFFNESS);
      vehicle.setWheelFrictionSlip(i, car.grip);
      vehicle.setWheelMaxSuspensionForce(i, maxForce);
    });
    // Queries see the colliders only after collision detection has run once: a step of 0 s
    // with no gravity and no hooks, as the Rust world's first.
    world.gravity = { x: 0.0, y: 0.0, z: 0.0 };
    world.timestep = 0.0;
    world.step();
    world.gravity = { x: 0.0, y: -GRAVITY, z: 0.0 };
    world.timestep = DECISION_DT;
    const w = { world, chassis, vehicle, road: road.handle, skip: false };
    // RoadContacts: the chassis–road pair left out while `skip`; every other pair as usual.
    w.hooks = {
      filterContactPair: (c1, c2) => ((c1 === w.road || c2 === w.road) && w.skip ? null : R.SolverFlags.COMPUTE_IMPULSE),
      filterIntersectionPair: () => true,
    };
    return w;
  }

  /** A run's state after a reset with `seed` (`reset_on(0, seed)`, env.rs). */
  reset(seed) {
    const rng = ChaCha8Rng.seedFromU64(seed);
    const start = this.road.nearestAlong(this.road.starts[0] + START_S);
    const sample = this.road.samples[start];
    const offset = rng.randomRange(-START_JITTER_M, START_JITTER_M);
    const turn = rng.randomRange(-START_JITTER_DEG, START_JITTER_DEG) * (Math.PI / 180.0);
    const p = across(sample, offset);
    return {
      w: this.world(p.map(f32), f32(sample.heading + turn)),
      nearest: start,
      along: sample.s,
      steps: 0,
      airSteps: 0,
      looseSteps: 0,
      flippedSteps: 0,
      outcome: null,
    };
  }

  /** Frees a run's world. */
  release(run) {
    if (!run.w) return;
    run.w.world.removeVehicleController(run.w.vehicle);
    run.w.world.free();
    run.w = null;
  }

  /** Distance down to the road or an obstacle from each of `origins`, up to `max` (`cast_down`). */
  castDown(run, origins, max, out) {
    const { world, chassis } = run.w;
    origins.forEach((o, k) => {
      this.ray.origin = { x: o[0], y: o[1], z: o[2] };
      const hit = world.castRay(this.ray, max, true, undefined, undefined, undefined, chassis);
      out[k] = hit ? Math.min(hit.timeOfImpact, max) : max;
    });
    return out;
  }

  /** The chassis's pose and motion, float32. */
  body(run) {
    const b = run.w.chassis;
    const t = b.translation();
    const r = b.rotation();
    const v = b.linvel();
    const a = b.angvel();
    return { position: [t.x, t.y, t.z], rotation: [r.x, r.y, r.z, r.w], velocity: [v.x, v.y, v.z], spin: [a.x, a.y, a.z] };
  }

  /** The car's heading in the level (`yaw`, env.rs): atan2(-F.z, F.x) of its forward axis F. */
  yaw(rotation) {
    const forward = rotate(rotation, [1.0, 0.0, 0.0]);
    return f32(Math.atan2(-forward[2], forward[0]));
  }

  /** Distance along the road of the point of the centre line nearest `position` (`along_at`). */
  alongAt(run, position) {
    const sample = this.road.samples[run.nearest];
    const hs = Math.sin(sample.heading);
    const hc = Math.cos(sample.heading);
    // RoadSample::forward, normalized with its slope.
    const n = Math.sqrt(hc * hc + sample.slope * sample.slope + hs * hs);
    const f = [hc / n, sample.slope / n, -hs / n];
    const flat = Math.sqrt(f[0] * f[0] + f[2] * f[2]);
    const ahead = ((position[0] - sample.centre[0]) * f[0] + (position[2] - sample.centre[2]) * f[2]) / flat;
    return Math.min(Math.max(sample.s + ahead, 0.0), this.road.length);
  }

  /** Signed horizontal distance of `position` left of the centre line, m (`lateral_offset`). */
  lateralOffset(run, position) {
    const sample = this.road.samples[run.nearest];
    const s = Math.sin(sample.heading);
    const c = Math.cos(sample.heading);
    return -(position[0] - sample.centre[0]) * s - (position[2] - sample.centre[2]) * c;
  }

  /** The centre line's points 8, 16, 26, 40, 60 m further along than the car (`centre_line_ahead`). */
  centreLineAhead(run) {
    return LOOK_AHEAD.map((a) => this.road.samples[this.road.nearestAlong(run.along + a)].centre);
  }

  /** The fan's 20 distances down (`fan_hits`): rows 5-30 m ahead, each from 7 m right to 7 m left. */
  fanHits(run, body = this.body(run)) {
    const level = rotationY(this.yaw(body.rotation));
    const origins = [];
    for (const f of FAN_FORWARD) {
      for (const l of FAN_LEFT) origins.push(add(body.position, rotate(level, [f, FAN_START_HEIGHT, -l])));
    }
    return this.castDown(run, origins, FAN_LENGTH, new Float32Array(FAN_SIZE));
  }

  /** The Solver's observation of a run into `out` (47 floats; `observe`, env.rs). */
  observe(run, out) {
    const body = this.body(run);
    const { position, rotation } = body;
    const intoCar = conjugate(rotation);
    const yaw = this.yaw(rotation);
    const intoLevel = conjugate(rotationY(yaw));
    const toGoal = rotate(intoLevel, sub(this.goal.map(f32), position));
    const bearing = f32(Math.atan2(-toGoal[2], toGoal[0]));
    const sample = this.road.samples[run.nearest];
    const roadBearing = wrap(f32(f32(sample.heading) - yaw));
    const velocity = rotate(intoCar, body.velocity);
    const spin = rotate(intoCar, body.spin);
    const up = rotate(intoCar, [0.0, 1.0, 0.0]);
    const lateral = f32(f32(this.lateralOffset(run, position)) / f32(0.5 * this.width));
    const ahead = this.centreLineAhead(run).flatMap((point) => {
      const local = rotate(intoLevel, sub(point.map(f32), position));
      return [local[0] / 60.0, local[2] / 20.0];
    });
    const state = [
      ...toGoal.map((x) => x / 100.0),
      Math.sin(bearing),
      Math.cos(bearing),
      ...velocity.map((x) => x / 20.0),
      ...spin,
      ...up,
      lateral,
      Math.sin(roadBearing),
      Math.cos(roadBearing),
      ...ahead,
    ];
    for (let i = 0; i < STATE_SIZE; i++) out[i] = state[i];
    const hits = this.fanHits(run, body);
    for (let i = 0; i < FAN_SIZE; i++) out[STATE_SIZE + i] = f32(f32(FAN_START_HEIGHT - hits[i]) / 6.0);
    return out;
  }

  /** The state a golden episode records (`port_state`, env.rs), for checking a port. */
  portState(run) {
    const body = this.body(run);
    const sample = this.road.samples[run.nearest];
    return {
      position: body.position,
      rotation_xyzw: body.rotation,
      velocity: body.velocity,
      angular_velocity: body.spin,
      goal: this.goal,
      road_point: sample.centre,
      road_heading: [sample.heading],
      centre_line_ahead: this.centreLineAhead(run).flat(),
      fan_hits: Array.from(this.fanHits(run, body)),
    };
  }

  /**
   * A run in a recorded state (a golden episode's `state`, `steps` decisions in): the chassis
   * there, the nearest cross-section the one at `road_point`, `along` from it (the start
   * cross-section's own after a reset). The wheels and contacts start afresh.
   */
  runFromState(state, steps) {
    const run = this.reset(0);
    const b = run.w.chassis;
    const [x, y, z] = state.position;
    const [qx, qy, qz, qw] = state.rotation_xyzw;
    b.setTranslation({ x, y, z }, true);
    b.setRotation({ x: qx, y: qy, z: qz, w: qw }, true);
    b.setLinvel({ x: state.velocity[0], y: state.velocity[1], z: state.velocity[2] }, true);
    b.setAngvel({ x: state.angular_velocity[0], y: state.angular_velocity[1], z: state.angular_velocity[2] }, true);
    run.nearest = this.road.nearest(state.road_point);
    run.steps = steps;
    run.along = steps === 0 ? this.road.samples[run.nearest].s : this.alongAt(run, state.position.map(f32));
    return run;
  }

  /** The chassis's centre, as a golden episode records the run's position. */
  position(run) {
    return this.body(run).position;
  }

  /** Whether the chassis box stays clear of the road this step, by the wheels' ray casts (`chassis_clear`, car.rs). */
  chassisClear(w) {
    const { chassis, vehicle } = w;
    const r = chassis.rotation();
    const down = rotate([r.x, r.y, r.z, r.w], [0.0, -1.0, 0.0]);
    let low = Infinity;
    let high = -Infinity;
    let closing = 0.0;
    for (let i = 0; i < WHEELS.length; i++) {
      if (!vehicle.wheelIsInContact(i)) return false;
      const ground = vehicle.wheelGroundObject(i);
      if (!ground || ground.handle !== w.road) return false;
      const nv = vehicle.wheelContactNormal(i);
      const hv = vehicle.wheelHardPoint(i);
      const cv = vehicle.wheelContactPoint(i);
      const normal = [nv.x, nv.y, nv.z];
      const bottom = add([hv.x, hv.y, hv.z], scale(down, BOTTOM_BELOW_WHEELS));
      const height = dot(sub(bottom, [cv.x, cv.y, cv.z]), normal);
      low = Math.min(low, height);
      high = Math.max(high, height);
      const v = chassis.velocityAtPoint({ x: bottom[0], y: bottom[1], z: bottom[2] });
      closing = Math.max(closing, f32(-dot([v.x, v.y, v.z], normal)));
    }
    const a = chassis.angvel();
    const reach = f32(f32(closing + f32(length([a.x, a.y, a.z]) * CORNER_LEVER)) * DECISION_DT);
    return f32(f32(low - f32(CORNER_SPREAD * f32(high - low))) - reach) > CLEARANCE_SLACK;
  }

  /** Whether an obstacle's plan lies within the chassis's reach this step (`obstacle_near`, car.rs). */
  obstacleNear(w) {
    if (this.obstacles.length === 0) return false;
    const p = w.chassis.translation();
    const v = w.chassis.linvel();
    const reach = f32(f32(length(CHASSIS_HALF) + f32(length([v.x, v.y, v.z]) * DECISION_DT)) + 0.5);
    return this.obstacles.some(({ plan: [x0, z0, x1, z1] }) =>
      p.x > f32(x0 - reach) && p.x < f32(x1 + reach) && p.z > f32(z0 - reach) && p.z < f32(z1 + reach),
    );
  }

  /**
   * One decision of a run under `action` ({throttle, steer}, already clipped): the controls,
   * the wheels, one physics step (`RacingWorld::step`, car.rs), then the run's bookkeeping
   * (`SolverEnv::step`, env.rs). Returns the outcome once the run has ended, else null.
   */
  step(run, action) {
    if (run.outcome) return run.outcome;
    const w = run.w;
    const car = this.car;
    const throttle = Math.min(Math.max(action.throttle, -1.0), 1.0);
    const steer = f32(Math.min(Math.max(action.steer, -1.0), 1.0) * car.maxSteer);
    const engine = f32(f32(0.5 * car.engineForce) * Math.max(throttle, 0.0));
    const brake = f32(car.brakeImpulse * Math.max(-throttle, 0.0));
    for (let i = 0; i < WHEELS.length; i++) {
      const front = i < 2;
      w.vehicle.setWheelSteering(i, front ? steer : 0.0);
      w.vehicle.setWheelEngineForce(i, front ? 0.0 : engine);
      w.vehicle.setWheelBrake(i, brake);
    }
    // The wheels' rays see fixed colliders only (the chassis excluded by rapier.js itself).
    w.vehicle.updateVehicle(DECISION_DT, this.RAPIER.QueryFilterFlags.EXCLUDE_DYNAMIC);
    w.skip = this.chassisClear(w);
    w.world.integrationParameters.maxCcdSubsteps = !w.skip || this.obstacleNear(w) ? 1 : 0;
    w.world.step(undefined, w.hooks);

    run.steps += 1;
    const body = this.body(run);
    const position = body.position;
    run.nearest = this.road.nearest(position, run.nearest, 8);
    const sample = this.road.samples[run.nearest];
    run.along = this.alongAt(run, position);
    let wheels = 0;
    for (let i = 0; i < WHEELS.length; i++) if (w.vehicle.wheelIsInContact(i)) wheels++;
    if (wheels === 0 && this.castDown(run, [position], f32(2.0 * AIR_HEIGHT), [0])[0] > AIR_HEIGHT) run.airSteps++;
    const beyondEdge = Math.abs(this.lateralOffset(run, position)) > 0.5 * this.width;
    run.looseSteps = wheels === 0 && beyondEdge ? run.looseSteps + 1 : 0;
    const up = rotate(body.rotation, [0.0, 1.0, 0.0]);
    run.flippedSteps = up[1] < FLIP_UP ? run.flippedSteps + 1 : 0;
    if (run.along >= this.road.length - FINISH_LENGTH && !beyondEdge) run.outcome = "Success";
    else if (position[1] < sample.centre[1] - BELOW_ROAD || f32(run.looseSteps * DECISION_DT) >= OFF_ROAD_S) run.outcome = "OffRoad";
    else if (f32(run.flippedSteps * DECISION_DT) >= FLIP_S) run.outcome = "Flipped";
    else if (run.steps >= this.maxSteps) run.outcome = "TimedOut";
    return run.outcome;
  }

  /** What a run's result reports beside its seed and outcome (`trial_result`, env.rs). */
  summary(run) {
    return {
      steps: run.steps,
      progress: Math.min(Math.max(run.along / this.road.length, 0.0), 1.0),
      segment: this.road.samples[run.nearest].segment,
      airSteps: run.airSteps,
    };
  }
}

/** An obstacle's plan bounding box [x0, z0, x1, z1] widened by the margin (`obstacle_plans`). */
function planBox(centre, ex, ez) {
  return [
    f32(f32(centre[0] - ex) - PLAN_MARGIN),
    f32(f32(centre[2] - ez) - PLAN_MARGIN),
    f32(f32(centre[0] + ex) + PLAN_MARGIN),
    f32(f32(centre[2] + ez) + PLAN_MARGIN),
  ];
}

// ---------------------------------------------------------------------------------------------
// The policy.

/**
 * An exported racing Solver: the graph (with its unclipped means exposed) and its sampling
 * (ActMode::Sample: throttle then steer; deterministic: the means); `act` and `play` in
 * `GameSolver` (solver.mjs), each run in its own world.
 */
export class RacingSolver extends GameSolver {
  /**
   * @param {object} ort an onnxruntime module (onnxruntime-node or onnxruntime-web)
   * @param {Uint8Array} onnx the graph's bytes (`arlpcg export-policy`, contract plain)
   * @param {object} sidecar the parsed sidecar (S.onnx.json); needs `sampling`
   * @param {object} [options] `sessionOptions` for onnxruntime
   */
  static async load(ort, onnx, sidecar, options = {}) {
    const network = await SolverNetwork.load(ort, onnx, sidecar, {
      game: "racing",
      observationSize: RACING_SOLVER_OBSERVATION_SIZE,
      sessionOptions: options.sessionOptions,
    });
    return new RacingSolver(network, RACING_SOLVER_OBSERVATION_SIZE);
  }

  /** The action a row (throttle, steer) stands for (`CarAction::from_policy_row`: clipped to [-1, 1]). */
  decode(row) {
    return { throttle: clipAction(row[0]), steer: clipAction(row[1]) };
  }
}
