// Platform levels from a seed, outside arlpcg: the blocks `arlpcg generate --policies DIR
// --aux=λ --seed S` writes, rebuilt from the Generator's ONNX export (`arlpcg export-policy
// DIR/generator.safetensors --out G.onnx`: G.onnx and its sidecar G.onnx.json), the seed and λ.
// An ES module with no build step and no dependency of its own: the caller hands it an
// onnxruntime module (onnxruntime-node, or onnxruntime-web in a page), so it runs under node and
// in a browser alike.
//
//   import * as ort from "onnxruntime-node"; // or "onnxruntime-web"
//   import { PlatformGenerator } from "./web/levels.mjs";
//   const generator = await PlatformGenerator.load(ort, onnxBytes, sidecarJson);
//   const level = await generator.build({ seed: 7, aux: -1 });
//   // level.goal, level.start, level.blocks[i] = { distance, angle, size, height, position, heading }
//
// What it reproduces (the Rust it follows, in arlpcg's sources): the goal and start heading
// drawn from the seed (`goal_and_start`, crates/core/src/game/platform/rules.rs); the build
// loop (`build_level`, src/services/generation.rs): up to the sidecar's `attempts` tries of at
// most `max_pieces` blocks, each block the Generator's observation (`observe`,
// crates/core/src/game/platform/generator.rs) through the graph (its normalizer is inside),
// sampled as `ActorCritic::choose` samples (crates/core/src/rl/policy.rs: the unclipped mean
// plus std times a standard normal, drawn column by column from the level's one ChaCha8 stream),
// turned into a block (`block_from_action`, with the reach cut of reach.rs) and placed or refused
// (`PlatformTrack::push`, crates/core/src/level/platform.rs); a refused block or a spent budget
// starts the next attempt on the same stream, a block within reach of the goal completes the
// level. The random streams are in rng.mjs.
//
// Limits: the platform game here (racing: racing.mjs); one λ for the whole level (no λ curve, no kept
// prefix, no `--draw`, no `--target-success`); the built-in character unless the caller gives
// a profile's piece rules *with its measured reach table* (arlpcg measures a profile's reach
// by simulation, which this module does not do); style knobs and an ability-aware Generator's
// ability columns are filled as given (default 0: no preference, our character).

import { ChaCha8Rng } from "./rng.mjs";
import { exposeMeans } from "./onnx-means.mjs";

/** The platform Generator's own observation columns (before knobs and abilities). */
export const PLATFORM_OBSERVATION_SIZE = 15;
/** The sharpest turn the reach table was measured over, degrees (`reach::MAX_TURN`). */
const MAX_TURN = 90.0;
/** The reach table's heights, m (`REACH_HEIGHTS`). */
const REACH_HEIGHTS = [-2.0, -1.0, 0.0, 1.0, 2.0];
/** The smallest edge gap a climb counts as reachable with, m (`GAP_RANGE.0`). */
const MIN_GAP = 1.0;
/** Goals are drawn this far away horizontally and this high (`GOAL_DISTANCE`, `GOAL_HEIGHT`). */
const GOAL_DISTANCE = [30.0, 70.0];
const GOAL_HEIGHT = [-6.0, 10.0];
/** A block completes the level within these of the goal (`GOAL_REACH_*`). */
const GOAL_REACH_HORIZONTAL = 3.0;
const GOAL_REACH_VERTICAL = 2.0;
/** The start block's side, m (`Start::default`). */
const START_SIZE = 6.0;
/** The built-in character's headroom, m (`HEADROOM`): sidecars before `headroom` was exported. */
const HEADROOM = 3.0;

// Rust's f64::to_radians and to_degrees multiply by these.
const RADIANS_PER_DEGREE = Math.PI / 180.0;
const DEGREES_PER_RADIAN = 180.0 / Math.PI;

/** Rust's f64::round: halves away from zero. */
function roundHalfAway(x) {
  return x < 0 ? -Math.round(-x) : Math.round(x);
}

/** The file's 1 mm and 0.001° (`quantize` in crates/core/src/level/params.rs). */
export function quantize(value) {
  return roundHalfAway(value * 1000.0) / 1000.0;
}

/** An angle in degrees into (-180, 180] (`wrap_degrees`). */
export function wrapDegrees(angle) {
  let wrapped = angle % 360.0;
  if (wrapped < 0.0) wrapped += 360.0;
  return wrapped > 180.0 ? wrapped - 360.0 : wrapped;
}

/** The plan direction (x, z) of a heading in degrees (`heading_direction`). */
export function headingDirection(heading) {
  const h = heading * RADIANS_PER_DEGREE;
  return [Math.cos(h), -Math.sin(h)];
}

/** The heading in degrees of the plan direction (x, z) (`direction_heading`). */
export function directionHeading(x, z) {
  return Math.atan2(-z, x) * DEGREES_PER_RADIAN;
}

export function clamp(x, lo, hi) {
  return x < lo ? lo : x > hi ? hi : x;
}

/** `ParamRange::from_unit`: -1 the least, +1 the most, linearly. */
export function fromUnit(t, lo, hi) {
  const u = clamp(t, -1.0, 1.0);
  return lo + (u + 1.0) * 0.5 * (hi - lo);
}

/** The goal and start heading of level `seed`, and the stream its other draws continue from. */
export function goalAndStart(seed) {
  const rng = ChaCha8Rng.seedFromU64(seed);
  const heading = rng.randomRange(-180.0, 180.0);
  const distance = rng.randomRange(GOAL_DISTANCE[0], GOAL_DISTANCE[1]);
  const height = rng.randomRange(GOAL_HEIGHT[0], GOAL_HEIGHT[1]);
  const [x, z] = headingDirection(heading);
  const goal = [quantize(distance * x), quantize(height), quantize(distance * z)];
  const start = {
    position: [0.0, 0.0, 0.0],
    heading: quantize(rng.randomRange(-180.0, 180.0)),
    size: START_SIZE,
  };
  return { goal, start, rng };
}

/** A player's reach (`Reach` in crates/core/src/game/platform/reach.rs). */
export class Reach {
  /** @param {number[]} table the largest edge gap at each of REACH_HEIGHTS, m */
  constructor(table) {
    if (table.length !== REACH_HEIGHTS.length) throw new Error("a reach table has 5 gaps");
    this.table = table;
    // Going up from 0 m, the last height whose gap is at least MIN_GAP before the first not.
    let climb = null;
    for (let i = 0; i < REACH_HEIGHTS.length; i++) {
      if (REACH_HEIGHTS[i] < 0.0) continue;
      if (!(table[i] >= MIN_GAP)) break;
      climb = REACH_HEIGHTS[i];
    }
    this.maxClimb = climb ?? REACH_HEIGHTS[0];
  }

  /** The largest edge gap at a height change, interpolated linearly (`max_gap`). */
  maxGap(height) {
    const h = clamp(height, REACH_HEIGHTS[0], this.maxClimb);
    let i = 0;
    for (let k = REACH_HEIGHTS.length - 1; k >= 0; k--) {
      if (REACH_HEIGHTS[k] <= h) {
        i = k;
        break;
      }
    }
    i = Math.min(i, 3);
    const t = (h - REACH_HEIGHTS[i]) / (REACH_HEIGHTS[i + 1] - REACH_HEIGHTS[i]);
    return this.table[i] + t * (this.table[i + 1] - this.table[i]);
  }
}

function dot(a, b) {
  return a[0] * b[0] + a[1] * b[1];
}

function axesOf(p) {
  const [x, z] = headingDirection(p.heading);
  return [
    [x, z],
    [-z, x],
  ];
}

/** Whether the square footprints of two platforms meet (separating axes; `footprint_intersects`). */
function footprintsMeet(self, other) {
  const delta = [other.position[0] - self.position[0], other.position[2] - self.position[2]];
  const mine = axesOf(self);
  const theirs = axesOf(other);
  const radius = (p, axes, axis) =>
    0.5 * p.size * (Math.abs(dot(axes[0], axis)) + Math.abs(dot(axes[1], axis)));
  for (const axis of [...mine, ...theirs]) {
    if (!(Math.abs(dot(delta, axis)) < radius(self, mine, axis) + radius(other, theirs, axis))) {
      return false;
    }
  }
  return true;
}

/** A platform track as `PlatformTrack` builds it: the start block, then each block placed. */
class Track {
  constructor(start, headroom) {
    this.platforms = [{ position: start.position.slice(), heading: wrapDegrees(start.heading), size: start.size }];
    this.blocks = [];
    this.headroom = headroom;
  }

  get last() {
    return this.platforms[this.platforms.length - 1];
  }

  /** `Platform::place`: the block's top centre and heading from the last platform. */
  preview(block) {
    const last = this.last;
    const heading = wrapDegrees(last.heading + block.angle);
    const [dx, dz] = headingDirection(heading);
    return {
      position: [
        last.position[0] + block.distance * dx,
        last.position[1] + block.height,
        last.position[2] + block.distance * dz,
      ],
      heading,
      size: block.size,
    };
  }

  /** `PlatformTrack::push`: false (nothing placed) where the block meets one but the last. */
  push(block) {
    const candidate = this.preview(block);
    for (let i = 0; i < this.platforms.length - 1; i++) {
      const p = this.platforms[i];
      if (Math.abs(p.position[1] - candidate.position[1]) < this.headroom && footprintsMeet(p, candidate)) {
        return false;
      }
    }
    this.blocks.push(block);
    this.platforms.push(candidate);
    return true;
  }
}

/** Whether a platform's top centre is within reach of the goal (`Platform::reaches`). */
function reaches(p, goal) {
  const horizontal = Math.hypot(goal[0] - p.position[0], goal[2] - p.position[2]);
  return horizontal <= GOAL_REACH_HORIZONTAL && Math.abs(goal[1] - p.position[1]) <= GOAL_REACH_VERTICAL;
}

/** The Generator's 15 observation columns of a track at λ (`observe`), into `out` from 0. */
export function observe(track, goal, aux, maxBlocks, out) {
  const last = track.last;
  const [fx, fz] = headingDirection(last.heading);
  const local = (point) => {
    const d0 = point[0] - last.position[0];
    const d1 = point[1] - last.position[1];
    const d2 = point[2] - last.position[2];
    return [d0 * fx + d2 * fz, d1, d0 * fz - d2 * fx];
  };
  const toGoal = local(goal);
  const goalDistance = Math.hypot(toGoal[0], toGoal[2]);
  const bearing = Math.atan2(toGoal[2], toGoal[0]);
  const n = track.platforms.length;
  const previous = n > 1 ? track.platforms[n - 2] : null;
  const turn = n > 1 ? track.blocks[n - 2].angle * RADIANS_PER_DEGREE : 0.0;
  const prev = previous ? local(previous.position).map((x) => x / 10.0) : [0.0, 0.0, 0.0];
  const values = [
    toGoal[0] / 50.0,
    toGoal[1] / 50.0,
    toGoal[2] / 50.0,
    Math.sin(bearing),
    Math.cos(bearing),
    goalDistance / 50.0,
    last.size / 6.0,
    prev[0],
    prev[1],
    prev[2],
    previous ? previous.size / 6.0 : 0.0,
    Math.sin(turn),
    Math.cos(turn),
    1.0 - track.blocks.length / maxBlocks,
  ];
  for (let i = 0; i < values.length; i++) out[i] = Math.fround(values[i]);
  out[14] = Math.fround(aux);
}

/** The block an action row stands for (`block_from_action`). */
export function blockFromAction(track, goal, row, rules, reach) {
  const unit = (v) => (Number.isNaN(v) ? 0.0 : v);
  const last = track.last;
  const dx = goal[0] - last.position[0];
  const dz = goal[2] - last.position[2];
  const bearing = directionHeading(dx, dz);
  const turn = fromUnit(unit(row[1]), -180.0, 180.0);
  const sharpest = Math.min(rules.max_turn, MAX_TURN);
  const block = {
    distance: quantize(fromUnit(unit(row[0]), rules.min_distance, rules.max_distance)),
    angle: quantize(clamp(wrapDegrees(bearing - last.heading + quantize(turn)), -sharpest, sharpest)),
    size: quantize(fromUnit(unit(row[2]), rules.min_size, rules.max_size)),
    height: quantize(fromUnit(unit(row[3]), rules.min_height, rules.max_height)),
  };
  const rise = goal[1] - last.position[1];
  const onCourse = rise * Math.min(block.distance / Math.max(Math.hypot(dx, dz), 1e-6), 1.0);
  block.height = quantize(
    Math.min(clamp(onCourse + block.height, rules.min_height, rules.max_height), reach.maxClimb),
  );
  // Never beyond the character's reach (nor below the shortest distance).
  const longest = reach.maxGap(block.height) + 0.5 * (last.size + block.size);
  block.distance = quantize(Math.max(Math.min(block.distance, longest), rules.min_distance));
  return block;
}

/**
 * An exported Generator's network and sampling, for either game: the graph with its unclipped
 * means exposed, and `choose`, which samples an action row as `ActorCritic::choose` does.
 */
export class GeneratorNetwork {
  /**
   * @param {object} ort an onnxruntime module (onnxruntime-node or onnxruntime-web)
   * @param {Uint8Array} onnx the graph's bytes (`arlpcg export-policy`, contract plain)
   * @param {object} sidecar the parsed sidecar (G.onnx.json); needs `sampling` and `generator`
   * @param {string} game the game the Generator must build for
   * @param {object} [options] `sessionOptions` for onnxruntime
   */
  static async load(ort, onnx, sidecar, game, options = {}) {
    GeneratorNetwork.check(sidecar, game);
    const { bytes, meanOutput } = exposeMeans(onnx);
    const session = await ort.InferenceSession.create(bytes, options.sessionOptions ?? {});
    return new GeneratorNetwork(ort, session, meanOutput, sidecar);
  }

  /** Throws unless `sidecar` is a plain export's of a `game` Generator with its build rules. */
  static check(sidecar, game) {
    if (sidecar.format !== "arlpcg-onnx" || sidecar.game !== game || sidecar.role !== "generator") {
      throw new Error(`not a ${game} Generator's sidecar: ${sidecar.game} ${sidecar.role}`);
    }
    if (sidecar.profile !== "plain") throw new Error("export the Generator with --contract plain");
    if (!sidecar.sampling || !sidecar.generator) {
      throw new Error("the sidecar has no `sampling` or `generator`: export it again with a newer arlpcg");
    }
  }

  /** `ort`, `session`, `meanOutput`: the graph (none for a subclass with its own `means`). */
  constructor(ort, session, meanOutput, sidecar) {
    this.ort = ort;
    this.session = session;
    this.meanOutput = meanOutput;
    this.input = sidecar.inputs[0].name;
    this.observationSize = sidecar.inputs[0].shape[1];
    this.std = sidecar.sampling.std.map(Math.fround);
    this.maxPieces = sidecar.generator.max_pieces;
    this.attempts = sidecar.generator.attempts;
    this.builtIn = flatRules(sidecar.generator.piece_rules);
  }

  /** The actor's unclipped means for one raw observation. */
  async means(observation) {
    const tensor = new this.ort.Tensor("float32", observation, [1, observation.length]);
    const result = await this.session.run({ [this.input]: tensor }, [this.meanOutput]);
    return result[this.meanOutput].data;
  }

  /** The continuous actions sampled for one raw observation (`choose`, ActMode::Sample). */
  async choose(observation, rng) {
    const mean = await this.means(observation);
    const action = new Float32Array(this.std.length);
    for (let k = 0; k < this.std.length; k++) {
      const noise = rng.standardNormalF32();
      action[k] = Math.fround(mean[k] + Math.fround(this.std[k] * noise));
    }
    return action;
  }
}

/** A loaded platform Generator. */
export class PlatformGenerator {
  /**
   * @param {object} ort an onnxruntime module (onnxruntime-node or onnxruntime-web)
   * @param {Uint8Array} onnx the graph's bytes (`arlpcg export-policy`, contract plain)
   * @param {object} sidecar the parsed sidecar (G.onnx.json); needs `sampling` and `generator`
   * @param {object} [options] `sessionOptions` for onnxruntime
   */
  static async load(ort, onnx, sidecar, options = {}) {
    return new PlatformGenerator(await GeneratorNetwork.load(ort, onnx, sidecar, "platform", options));
  }

  constructor(network) {
    this.network = network;
  }

  /**
   * The level of `seed` at λ `aux`: its goal, start and blocks as `arlpcg generate` writes
   * them, with `attempt` (from 0) the attempt that completed it; throws where no attempt does.
   * @param {{seed: number|bigint, aux?: number, knobs?: number[], abilities?: number[],
   *          rules?: object}} request `rules`: a profile's piece rules (the sidecar's
   *          `generator.piece_rules` names, its measured `reach_table` and `headroom`)
   */
  async build({ seed, aux = 0.0, knobs = [], abilities = [], rules = null }) {
    const net = this.network;
    const pieceRules = rules ? flatRules(rules) : net.builtIn;
    const reach = new Reach(pieceRules.reach_table);
    const headroom = pieceRules.headroom ?? HEADROOM;
    const { goal, start, rng } = goalAndStart(seed);
    const observation = new Float32Array(net.observationSize);
    const extra = [...knobs, ...abilities];
    for (let attempt = 0; attempt < net.attempts; attempt++) {
      const track = new Track(start, headroom);
      while (track.blocks.length < net.maxPieces) {
        observe(track, goal, aux, net.maxPieces, observation);
        for (let i = PLATFORM_OBSERVATION_SIZE; i < net.observationSize; i++) {
          observation[i] = Math.fround(extra[i - PLATFORM_OBSERVATION_SIZE] ?? 0.0);
        }
        const action = await net.choose(observation, rng);
        const block = blockFromAction(track, goal, action, pieceRules, reach);
        if (!track.push(block)) break;
        if (reaches(track.last, goal)) {
          return {
            seed,
            aux,
            goal,
            start,
            attempt,
            blocks: track.blocks.map((b, i) => ({
              ...b,
              position: track.platforms[i + 1].position,
              heading: track.platforms[i + 1].heading,
            })),
          };
        }
      }
    }
    throw new Error(`the Generator built no valid level toward goal ${goal} at λ = ${aux} in ${net.attempts} attempts`);
  }
}

/** Piece rules with each one-value list as its value (the sidecar's lists). */
export function flatRules(rules) {
  const out = {};
  for (const [name, value] of Object.entries(rules)) {
    out[name] = name === "reach_table" ? value : Array.isArray(value) ? value[0] : value;
  }
  return out;
}
