// The platform Solver outside arlpcg: an exported Solver (`arlpcg export-policy
// policies/platform/solver.safetensors --out S.onnx`: S.onnx and its sidecar S.onnx.json) playing
// a platform level in rapier's JavaScript build, as `arlpcg verify` plays it in rapier3d.
// An ES module with no build step and no dependency of its own: the caller hands it an
// onnxruntime module (onnxruntime-node, or onnxruntime-web in a page) and an initialized rapier
// module (`@dimforge/rapier3d-compat`, after `await RAPIER.init()`).
//
//   import * as ort from "onnxruntime-node";
//   import RAPIER from "@dimforge/rapier3d-compat";
//   import { PlatformSolver, PlatformCourse, parsePlatformLevel } from "./web/platform-solver.mjs";
//   await RAPIER.init();
//   const solver = await PlatformSolver.load(ort, onnxBytes, sidecarJson);
//   const course = new PlatformCourse(RAPIER, parsePlatformLevel(levelYamlText));
//   const results = await solver.play(course, { trials: 20, seed: 0 });
//   // results[i] = { seed, outcome: "Success" | "Fell" | "TimedOut", steps, furthest, progress }
//   course.free();
//
// What it reproduces (the Rust it follows, in arlpcg's sources):
// - the blocks (`PlatformTrack::push`/`Platform::place`, crates/core/src/level/platform.rs: each
//   block placed from the one before by its distance, angle and height, as a level file is read;
//   not the file's rounded `position`) as fixed cuboid colliders, 1 m thick, their top centre at
//   the block's position (`PlatformWorld`, crates/core/src/game/platform/world.rs);
// - the character (crates/core/src/game/platform/character.rs): a capsule (radius 0.4 m, 1.8 m
//   tall) moved by rapier's KinematicCharacterController (offset 0.02 m, snap to ground 0.1 m,
//   no autostep, slide; rapier's other defaults) under the game's own velocity rules (run 8 m/s,
//   backward at half, turn 270°/s, ground acceleration 60 m/s², air 6 m/s², jump 9.25 m/s,
//   gravity 20 m/s²), two physics steps of 1/60 s per decision at 30 Hz;
// - the reset (`reset_on`, crates/core/src/game/platform/env.rs; docs/engines.md, "A reset,
//   from `spawn`"), drawn from the trial's ChaCha8 stream as rand draws it;
// - the observation (`observe`, env.rs; docs/engines.md, "Porting a policy" and "The state a
//   game computes for its port"): goal, next block, velocity, bearing, grounded, time left and
//   the 25-ray height map, with the game's "stood on" rule for the furthest block;
// - the run's end (`Course::after_decision`, crates/core/src/game/platform/course.rs): success on
//   the last block, a fall 5 m below the lowest block's top, or the time limit
//   (10 s + 4 s per block);
// - the actions as `verify` draws them (`ActorCritic::draw`, crates/core/src/rl/policy.rs,
//   ActMode::Sample): per trial i a ChaCha8 stream seeded SEED + i (a stream of its own beside the
//   reset's, seeded alike), each decision the continuous actions mean + std·n (n standard normal,
//   float32, in column order; the mean unclipped) and then the jump on when a uniform f32 draw is
//   below its probability; the game clips forward and turn to [-1, 1] and jumps when on.
//
// The arithmetic is the game's float32 (Math.fround where Rust rounds). What differs from the
// Rust game is only what rapier's JS build and onnxruntime compute: see docs/engines.md,
// "Playing a Solver in rapier.js".

import { ChaCha8Rng } from "./rng.mjs";
import { headingDirection, quantize, wrapDegrees } from "./levels.mjs";
import { readLevelYaml } from "./level-file.mjs";
import {
  GameSolver,
  SolverNetwork,
  add,
  clipAction,
  dot,
  f32,
  length,
  randomRangeF32,
  rotate,
  rotationY,
  scale,
  sub,
} from "./solver.mjs";

// Kept here for callers of this module's earlier versions.
export { randomF32, randomRangeF32 } from "./solver.mjs";

/** The built-in character (`CharacterProfile::default`, crates/core/src/level/profile/abilities.rs). */
export const BUILT_IN_CHARACTER = Object.freeze({
  run_speed: 8.0,
  jump_speed: 9.25,
  gravity: 20.0,
  ground_accel: 60.0,
  air_accel: 6.0,
  turn_rate: 270.0,
  radius: 0.4,
  height: 1.8,
});

/** Backwards the character runs at this fraction of its run speed (`BACKWARD_FACTOR`). */
const BACKWARD_FACTOR = 0.5;
/** Physics steps per second and per decision (`PHYSICS_HZ`, `ACTION_REPEAT`). */
const PHYSICS_HZ = 60.0;
const ACTION_REPEAT = 2;
const PHYSICS_DT = f32(1.0 / PHYSICS_HZ);
const DECISION_DT = f32(ACTION_REPEAT / PHYSICS_HZ);
/** Every block is this thick; its position is its top face's centre (`BLOCK_THICKNESS`). */
const BLOCK_THICKNESS = 1.0;
/** The start block's side when a level gives none (`Start::default`). */
const START_SIZE = 6.0;
/** The character controller's settings (`PlatformWorld::new`, world.rs). */
const CONTROLLER_OFFSET = 0.02;
const SNAP_TO_GROUND = 0.1;
/** The height map (env.rs): rays ahead and to the left of the feet, from 2.2 m up, 8 m long. */
const HEIGHT_MAP_FORWARD = [-1.5, 0.0, 1.5, 3.0, 4.5];
const HEIGHT_MAP_LEFT = [-3.0, -1.5, 0.0, 1.5, 3.0];
const RAY_START_HEIGHT = f32(2.2);
const RAY_LENGTH = 8.0;
/** The observation's length (`OBSERVATION_SIZE`): 15 state columns and the 25 rays. */
export const PLATFORM_SOLVER_OBSERVATION_SIZE = 40;
const STATE_SIZE = 15;
/** A run has fallen this far below the lowest block's top (`FALL_MARGIN`, course.rs). */
const FALL_MARGIN = 5.0;
/** Time allowed: this many seconds plus this many per block (course.rs). */
const TIME_BASE_S = 10.0;
const TIME_PER_BLOCK_S = 4.0;
/** "Stood on": the feet within this of a block's top (`standing_on`, env.rs). */
const STAND_HEIGHT = f32(0.2);
/** Rust's f32::to_radians multiplies by this float32 constant (π/180 in f32). */
const F32_RADIANS_PER_DEGREE = f32(f32(Math.PI) / 180.0);

// ---------------------------------------------------------------------------------------------
// Levels.

/**
 * The few fields of an arlpcg platform level file that a run needs: `start` (position, heading,
 * size), `goal` and each block's `distance`, `angle`, `size` and `height`. Reads the YAML
 * arlpcg writes (block style) and hand-written levels like levels/hand/staircase.yaml
 * (`readLevelYaml`, level-file.mjs: not YAML at large; pass a parsed object to `platformLevel`
 * otherwise).
 * @param {string} text
 */
export function parsePlatformLevel(text) {
  const doc = readLevelYaml(text);
  if (doc?.game !== undefined && doc.game !== "platform") throw new Error(`not a platform level: game ${doc.game}`);
  return platformLevel(doc);
}

/** A level object (parsed from a level file, YAML or JSON) checked and reduced to what a run needs. */
export function platformLevel(doc) {
  const start = doc.start ?? {};
  const need = (v, what) => {
    if (v === undefined || v === null) throw new Error(`level: missing ${what}`);
    return v;
  };
  const level = {
    start: {
      position: need(start.position, "start.position").map(Number),
      heading: Number(need(start.heading, "start.heading")),
      size: Number(start.size ?? START_SIZE),
    },
    goal: doc.goal?.map(Number),
    blocks: need(doc.blocks, "blocks").map((b, i) => ({
      distance: Number(need(b.distance, `blocks[${i}].distance`)),
      angle: Number(need(b.angle, `blocks[${i}].angle`)),
      size: Number(need(b.size, `blocks[${i}].size`)),
      height: Number(need(b.height, `blocks[${i}].height`)),
    })),
  };
  // No goal written: the last block's top, to the file's 1 mm (`into_level`,
  // crates/core/src/level/yaml/file.rs).
  if (!level.goal) level.goal = placePlatforms(level).at(-1).position.map(quantize);
  return level;
}

/**
 * The platforms as placed (f64, degrees): the start block, then each block from the one before
 * (`Platform::place`: heading wrapped, then distance along it and the height change).
 */
export function placePlatforms(level) {
  const out = [{ position: level.start.position.slice(), heading: level.start.heading, size: level.start.size }];
  for (const b of level.blocks) {
    const last = out[out.length - 1];
    const heading = wrapDegrees(last.heading + b.angle);
    const [dx, dz] = headingDirection(heading);
    out.push({
      position: [last.position[0] + b.distance * dx, last.position[1] + b.height, last.position[2] + b.distance * dz],
      heading,
      size: b.size,
    });
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// The world and the character.

/**
 * A level's blocks in a rapier.js world, and the runs played on it (one at a time or many side by
 * side: each run keeps its own state, and the character's collider is moved to it before each
 * query). Call `free()` when done: rapier.js's memory is WebAssembly's, not the garbage
 * collector's.
 */
export class PlatformCourse {
  /**
   * @param {object} RAPIER the rapier3d-compat module, initialized
   * @param {object} level from parsePlatformLevel or platformLevel
   * @param {object} [character] a profile's `character:` abilities (default: the built-in one)
   */
  constructor(RAPIER, level, character = BUILT_IN_CHARACTER) {
    this.RAPIER = RAPIER;
    // What an ability-aware Solver observes after the game's columns: each main ability
    // (jump speed, run speed, gravity) as value/ours - 1 (0 for ours; `ability_columns`).
    this.abilityPart = ["jump_speed", "run_speed", "gravity"].map((k) =>
      f32(character[k] / BUILT_IN_CHARACTER[k] - 1.0),
    );
    this.goal = level.goal.map(f32);
    this.body = {
      runSpeed: f32(character.run_speed),
      jumpSpeed: f32(character.jump_speed),
      gravity: f32(character.gravity),
      groundAccel: f32(character.ground_accel),
      airAccel: f32(character.air_accel),
      turnRate: f32(character.turn_rate),
      radius: f32(character.radius),
      halfHeight: f32(0.5 * character.height - character.radius),
    };
    this.body.centreOffset = f32(this.body.halfHeight + this.body.radius);
    // PlatformBox::from_platform: the top in f32, the heading in radians (f64, then f32).
    this.platforms = placePlatforms(level).map((p) => ({
      top: p.position.map(f32),
      heading: f32(p.heading * (Math.PI / 180.0)),
      size: f32(p.size),
    }));
    this.lowestTop = Math.min(...this.platforms.map((p) => p.top[1]));
    const blocks = this.platforms.length - 1;
    // Course::measure: ceil((10 s + 4 s per block) / decision dt), in f32.
    this.maxSteps = Math.ceil(f32(f32(TIME_BASE_S + f32(TIME_PER_BLOCK_S * blocks)) / DECISION_DT));

    this.world = new RAPIER.World({ x: 0.0, y: 0.0, z: 0.0 });
    this.world.timestep = PHYSICS_DT; // the controller's dt (move_shape's `dt`)
    const halfThickness = f32(0.5 * BLOCK_THICKNESS);
    for (const p of this.platforms) {
      const q = rotationY(p.heading);
      const half = f32(0.5 * p.size);
      const desc = RAPIER.ColliderDesc.cuboid(half, halfThickness, half)
        .setTranslation(p.top[0], f32(p.top[1] - halfThickness), p.top[2])
        .setRotation({ x: q[0], y: q[1], z: q[2], w: q[3] });
      this.world.createCollider(desc);
    }
    // One step with no bodies: puts the blocks in the broad phase that scene queries use.
    this.world.step();
    // The character's capsule, added after that step so it is never in the broad phase (the
    // Rust game's character is a shape, not a collider); its queries exclude it all the same.
    this.character = this.world.createCollider(RAPIER.ColliderDesc.capsule(this.body.halfHeight, this.body.radius));
    this.controller = this.world.createCharacterController(CONTROLLER_OFFSET);
    this.controller.enableSnapToGround(SNAP_TO_GROUND);
    this.controller.disableAutostep();
    this.controller.setSlideEnabled(true);
    this.ray = new RAPIER.Ray({ x: 0, y: 0, z: 0 }, { x: 0.0, y: -1.0, z: 0.0 });
  }

  free() {
    this.world.removeCharacterController(this.controller);
    this.world.free();
  }

  /** A run's state after a reset with `seed` on block 0 (`reset_on`, env.rs). */
  reset(seed) {
    const rng = ChaCha8Rng.seedFromU64(seed);
    const start = this.platforms[0];
    const reach = Math.min(Math.max(f32(f32(f32(0.5 * start.size) - this.body.radius) - 0.5), 0.0), 1.0);
    const a = randomRangeF32(rng, -reach, reach);
    const b = randomRangeF32(rng, -reach, reach);
    const offset = rotate(rotationY(start.heading), [a, 0.0, b]);
    const turn = f32(randomRangeF32(rng, -90.0, 90.0) * F32_RADIANS_PER_DEGREE);
    return {
      feet: add(start.top, offset),
      velocity: [0.0, 0.0, 0.0],
      yaw: f32(start.heading + turn),
      grounded: true,
      steps: 0,
      furthest: 0,
      outcome: null,
    };
  }

  /** The next platform to reach (`Course::next_index`). */
  nextIndex(run) {
    return Math.min(run.furthest + 1, this.platforms.length - 1);
  }

  /** The platform the character stands on, if grounded on one (`standing_on`, env.rs), else -1. */
  standingOn(run) {
    if (!run.grounded) return -1;
    const feet = run.feet;
    return this.platforms.findIndex((p) => {
      if (!(Math.abs(f32(feet[1] - p.top[1])) < STAND_HEIGHT)) return false;
      // PlatformBox::covers: the feet in the block's axes, its top grown by the radius.
      const local = rotate(rotationY(-p.heading), sub(feet, p.top));
      const half = f32(f32(0.5 * p.size) + this.body.radius);
      return Math.abs(local[0]) <= half && Math.abs(local[2]) <= half;
    });
  }

  /** The 25 height-map rays' distances to a hit (8 m: none), forward-major, right to left. */
  heightMapHits(run) {
    const forward = facing(run.yaw);
    const left = [forward[2], 0.0, f32(-forward[0])];
    const hits = new Float32Array(HEIGHT_MAP_FORWARD.length * HEIGHT_MAP_LEFT.length);
    let k = 0;
    for (const a of HEIGHT_MAP_FORWARD) {
      for (const b of HEIGHT_MAP_LEFT) {
        const o = add(add(add(run.feet, scale(forward, a)), scale(left, b)), [0.0, RAY_START_HEIGHT, 0.0]);
        this.ray.origin = { x: o[0], y: o[1], z: o[2] };
        const hit = this.world.castRay(this.ray, RAY_LENGTH, true, undefined, undefined, this.character);
        hits[k++] = hit ? hit.timeOfImpact : RAY_LENGTH;
      }
    }
    return hits;
  }

  /** The Solver's observation of a run into `out` (40 floats, and an ability-aware Solver's 3 abilities; `observe`, env.rs). */
  observe(run, out) {
    const forward = facing(run.yaw);
    const left = [forward[2], 0.0, f32(-forward[0])];
    const local = (v) => [dot(v, forward), v[1], dot(v, left)];
    const next = this.platforms[this.nextIndex(run)];
    const toGoal = sub(this.goal, run.feet);
    const toNext = sub(next.top, run.feet);
    const bearing = f32(Math.atan2(dot(toNext, left), dot(toNext, forward)));
    const state = [
      ...local(toGoal).map((x) => x / 50.0),
      length(toGoal) / 50.0,
      ...local(toNext).map((x) => x / 10.0),
      next.size / 6.0,
      ...local(run.velocity).map((x) => x / 10.0),
      Math.sin(bearing),
      Math.cos(bearing),
      run.grounded ? 1.0 : 0.0,
      f32(1.0 - f32(run.steps / this.maxSteps)),
    ];
    for (let i = 0; i < STATE_SIZE; i++) out[i] = state[i];
    const hits = this.heightMapHits(run);
    for (let i = 0; i < hits.length; i++) out[STATE_SIZE + i] = f32(f32(RAY_START_HEIGHT - hits[i]) / 4.0);
    // An ability-aware Solver's row is longer: the abilities follow.
    for (let i = PLATFORM_SOLVER_OBSERVATION_SIZE; i < out.length; i++) {
      out[i] = this.abilityPart[i - PLATFORM_SOLVER_OBSERVATION_SIZE];
    }
    return out;
  }

  /** The state a golden episode records (`port_state`, env.rs), for checking a port. */
  portState(run) {
    const next = this.platforms[this.nextIndex(run)];
    return {
      feet: run.feet,
      yaw: [run.yaw],
      velocity: run.velocity,
      grounded: [run.grounded ? 1 : 0],
      steps: [run.steps],
      max_steps: [this.maxSteps],
      goal: this.goal,
      next_block_top: next.top,
      next_block_size: [next.size],
      height_map_hits: Array.from(this.heightMapHits(run)),
    };
  }

  /**
   * A run in a recorded state (a golden episode's `state`, `steps` decisions in): the feet,
   * yaw, velocity and grounded flag as recorded, `furthest` the block before the recorded next
   * block.
   */
  runFromState(state, steps) {
    const next = this.platforms.findIndex((p) => p.top.every((v, k) => Math.abs(v - state.next_block_top[k]) < 1e-4));
    return {
      feet: state.feet.map(f32),
      velocity: state.velocity.map(f32),
      yaw: f32(state.yaw[0]),
      grounded: state.grounded[0] === 1,
      steps,
      furthest: next - 1,
      outcome: null,
    };
  }

  /** The feet, as a golden episode records the run's position. */
  position(run) {
    return run.feet;
  }

  /** What a run's result reports beside its seed and outcome. */
  summary(run) {
    const last = this.platforms.length - 1;
    return { steps: run.steps, furthest: run.furthest, progress: run.furthest / Math.max(last, 1) };
  }

  /** Moves the capsule (centred at `centre`) by `desired` through the blocks (`move_character`). */
  move(centre, desired) {
    this.character.setTranslation({ x: centre[0], y: centre[1], z: centre[2] });
    this.controller.computeColliderMovement(this.character, { x: desired[0], y: desired[1], z: desired[2] });
    const t = this.controller.computedMovement();
    return { translation: [t.x, t.y, t.z], grounded: this.controller.computedGrounded() };
  }

  /**
   * One decision of a run under `action` ({forward, turn, jump}, already clipped): the character's
   * two physics steps (`Character::step`, character.rs), then the run's bookkeeping
   * (`Course::after_decision`). Returns the outcome once the run has ended, else null.
   */
  step(run, action) {
    if (run.outcome) return run.outcome;
    const body = this.body;
    const dt = PHYSICS_DT;
    for (let substep = 0; substep < ACTION_REPEAT; substep++) {
      run.yaw = f32(run.yaw + f32(f32(action.turn * f32(body.turnRate * F32_RADIANS_PER_DEGREE)) * dt));
      const speed =
        action.forward >= 0.0
          ? f32(action.forward * body.runSpeed)
          : f32(f32(action.forward * body.runSpeed) * BACKWARD_FACTOR);
      const wanted = scale(facing(run.yaw), speed);
      const accel = run.grounded ? body.groundAccel : body.airAccel;
      let horizontal = [run.velocity[0], 0.0, run.velocity[2]];
      const change = sub(wanted, horizontal);
      const maxChange = f32(accel * dt);
      const changeLength = length(change);
      horizontal = changeLength <= maxChange ? wanted : add(horizontal, scale(change, f32(maxChange / changeLength)));
      let vertical = run.velocity[1];
      if (action.jump && run.grounded && substep === 0) vertical = body.jumpSpeed;
      // On the ground, snap-to-ground holds the character down (the game does not push it into
      // the floor: rapier's controller would now and then read the floor as a wall).
      if (!(run.grounded && vertical <= 0.0)) vertical = f32(vertical - f32(body.gravity * dt));
      const desired = scale([horizontal[0], vertical, horizontal[2]], dt);
      const moved = this.move(add(run.feet, [0.0, body.centreOffset, 0.0]), desired);
      run.feet = add(run.feet, moved.translation);
      // Blocked by a wall or a ceiling: lose the velocity into it.
      const velocity = [horizontal[0], vertical, horizontal[2]];
      if (Math.abs(f32(moved.translation[0] - desired[0])) > 1e-4 || Math.abs(f32(moved.translation[2] - desired[2])) > 1e-4) {
        velocity[0] = f32(moved.translation[0] / dt);
        velocity[2] = f32(moved.translation[2] / dt);
      }
      if (vertical > 0.0 && moved.translation[1] < f32(desired[1] - 1e-4)) velocity[1] = 0.0;
      run.grounded = moved.grounded && velocity[1] <= 0.0;
      if (run.grounded) velocity[1] = 0.0;
      run.velocity = velocity;
    }
    run.steps += 1;
    const standing = this.standingOn(run);
    if (standing > run.furthest) run.furthest = standing;
    const last = this.platforms.length - 1;
    if (run.furthest === last) run.outcome = "Success";
    else if (run.feet[1] < this.lowestTop - FALL_MARGIN) run.outcome = "Fell";
    else if (run.steps >= this.maxSteps) run.outcome = "TimedOut";
    return run.outcome;
  }
}

/** The unit vector a yaw faces, (cos, 0, -sin) in f32 (`Character::facing`). */
function facing(yaw) {
  return [f32(Math.cos(yaw)), 0.0, f32(-Math.sin(yaw))];
}

// ---------------------------------------------------------------------------------------------
// The policy.

/**
 * An exported platform Solver: the graph (with its unclipped means exposed) and its sampling
 * (`choose_per_row`, ActMode::Sample: forward, turn, then the jump; deterministic: the means and
 * the jump on at p ≥ 1/2); `act` and `play` in `GameSolver` (solver.mjs).
 */
export class PlatformSolver extends GameSolver {
  /**
   * @param {object} ort an onnxruntime module (onnxruntime-node or onnxruntime-web)
   * @param {Uint8Array} onnx the graph's bytes (`arlpcg export-policy`, contract plain)
   * @param {object} sidecar the parsed sidecar (S.onnx.json); needs `sampling`
   * @param {object} [options] `sessionOptions` for onnxruntime
   */
  static async load(ort, onnx, sidecar, options = {}) {
    const network = await SolverNetwork.load(ort, onnx, sidecar, {
      game: "platform",
      observationSize: PLATFORM_SOLVER_OBSERVATION_SIZE,
      sessionOptions: options.sessionOptions,
    });
    return new PlatformSolver(network, network.observationSize);
  }

  /** The action a row (forward, turn, jump) stands for (`PlatformAction::from_policy_row`: clipped to [-1, 1], NaN as 0; the jump on at 1). */
  decode(row) {
    return { forward: clipAction(row[0]), turn: clipAction(row[1]), jump: row[2] === 1.0 };
  }
}
