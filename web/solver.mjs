// What the JS Solvers share (web/platform-solver.mjs, web/racing-solver.mjs): the float32
// vector and quaternion arithmetic of glam (the math rapier3d and the games use), rand's float32
// draws, an exported Solver's graph with `verify`'s sampling, and the loop that plays runs side
// by side as `arlpcg verify` plays them one after another.
//
// A game's course (PlatformCourse, RacingCourse) gives the loop `reset(seed)` → run,
// `observe(run, row)`, `step(run, action)` → the outcome once the run has ended (else null),
// `summary(run)` → what a result reports beside seed and outcome, and may give `release(run)`
// (a run that holds rapier.js memory of its own).

import { ChaCha8Rng } from "./rng.mjs";
import { exposeMeans } from "./onnx-means.mjs";

export const f32 = Math.fround;

// ---------------------------------------------------------------------------------------------
// float32 vectors as glam computes them: [x, y, z] arrays of float32 values.

export const add = (a, b) => [f32(a[0] + b[0]), f32(a[1] + b[1]), f32(a[2] + b[2])];
export const sub = (a, b) => [f32(a[0] - b[0]), f32(a[1] - b[1]), f32(a[2] - b[2])];
export const scale = (a, s) => [f32(a[0] * s), f32(a[1] * s), f32(a[2] * s)];
export const dot = (a, b) => f32(f32(f32(a[0] * b[0]) + f32(a[1] * b[1])) + f32(a[2] * b[2]));
export const length = (a) => f32(Math.sqrt(dot(a, a)));
export const cross = (a, b) => [
  f32(f32(a[1] * b[2]) - f32(a[2] * b[1])),
  f32(f32(a[2] * b[0]) - f32(a[0] * b[2])),
  f32(f32(a[0] * b[1]) - f32(a[1] * b[0])),
];

/** `Quat::from_rotation_y(angle)` as [x, y, z, w]. */
export function rotationY(angle) {
  const half = f32(angle * 0.5);
  return [0.0, f32(Math.sin(half)), 0.0, f32(Math.cos(half))];
}

/** `Quat::inverse` of a unit quaternion: its conjugate. */
export const conjugate = (q) => [-q[0], -q[1], -q[2], q[3]];

/** `Quat * Vec3` (glam's mul_vec3a: v(w² - b·b) + b(2 v·b) + (b × v)(2w)). */
export function rotate(q, v) {
  const b = [q[0], q[1], q[2]];
  const w = q[3];
  return add(add(scale(v, f32(f32(w * w) - dot(b, b))), scale(b, f32(dot(v, b) * 2.0))), scale(cross(b, v), f32(w * 2.0)));
}

// ---------------------------------------------------------------------------------------------
// rand's float32 draws.

/** rand's `random_range(low..=high)` for f32: a u32's top 23 bits as [1, 2), minus 1, times the span, plus low. */
export function randomRangeF32(rng, low, high) {
  const bits = (rng.nextU32() >>> 9) | 0x3f800000;
  const view = new DataView(new ArrayBuffer(4));
  view.setUint32(0, bits);
  const value01 = f32(view.getFloat32(0) - 1.0);
  return f32(f32(value01 * f32(high - low)) + low);
}

/** rand's `random::<f32>()`: a u32's top 24 bits times 2⁻²⁴. */
export function randomF32(rng) {
  return (rng.nextU32() >>> 8) * 5.9604644775390625e-8;
}

// ---------------------------------------------------------------------------------------------
// The policy.

/**
 * An exported Solver's graph (with its unclipped means exposed) and `verify`'s sampling
 * (`ActorCritic::draw`, crates/core/src/rl/policy.rs, ActMode::Sample).
 */
export class SolverNetwork {
  /**
   * @param {object} ort an onnxruntime module (onnxruntime-node or onnxruntime-web)
   * @param {Uint8Array} onnx the graph's bytes (`arlpcg export-policy`, contract plain)
   * @param {object} sidecar the parsed sidecar (S.onnx.json); needs `sampling`
   * @param {{game: string, observationSize: number, sessionOptions?: object}} expect
   */
  static async load(ort, onnx, sidecar, { game, observationSize, sessionOptions = {} }) {
    if (sidecar.game !== game || sidecar.role !== "solver") {
      throw new Error(`not a ${game} Solver's export: ${sidecar.game} ${sidecar.role}`);
    }
    if (sidecar.profile !== "plain") throw new Error("export the Solver with --contract plain");
    if (!sidecar.sampling) throw new Error("the sidecar has no `sampling`: export it again with a newer arlpcg");
    const size = sidecar.inputs[0].shape[1];
    // An ability-aware Solver observes the character's main abilities after the game's columns.
    const abilities = sidecar.inputs[0].columns?.find((c) => c.name === "abilities")?.width ?? 0;
    if (size !== observationSize + abilities) {
      throw new Error(`this module plays the ${observationSize}-column ${game} Solver (and its abilities); this one observes ${size}`);
    }
    const { bytes, meanOutput } = exposeMeans(onnx);
    const session = await ort.InferenceSession.create(bytes, sessionOptions);
    return new SolverNetwork(ort, session, meanOutput, sidecar, size);
  }

  constructor(ort, session, meanOutput, sidecar, observationSize) {
    this.ort = ort;
    this.session = session;
    this.meanOutput = meanOutput;
    this.input = sidecar.inputs[0].name;
    this.observationSize = observationSize;
    this.std = sidecar.sampling.std.map(f32);
    this.continuous = this.std.length;
    this.binary = sidecar.outputs.some((o) => o.name === "binary_probabilities");
  }

  /**
   * The raw action rows of a batch of observations, each row's draws from its own stream
   * (`choose_per_row`): the continuous actions mean + std·n (float32, n rand_distr's
   * StandardNormal, in column order; the mean unclipped), then each binary action 1 when
   * `random::<f32>()` is below its probability. `deterministic`: the means and p ≥ 1/2, drawing
   * nothing (the graph's own outputs). The game clips the rows.
   */
  async act(rows, count, rngs, { deterministic = false } = {}) {
    const n = this.observationSize;
    const tensor = new this.ort.Tensor("float32", rows.subarray(0, count * n), [count, n]);
    const outputs = this.binary ? [this.meanOutput, "binary_probabilities"] : [this.meanOutput];
    const result = await this.session.run({ [this.input]: tensor }, outputs);
    const means = result[this.meanOutput].data;
    const probabilities = this.binary ? result.binary_probabilities.data : null;
    const c = this.continuous;
    const b = this.binary ? probabilities.length / count : 0;
    const out = [];
    for (let r = 0; r < count; r++) {
      const row = new Array(c + b);
      for (let k = 0; k < c; k++) {
        const mean = means[c * r + k];
        row[k] = deterministic ? mean : f32(mean + f32(this.std[k] * rngs[r].standardNormalF32()));
      }
      for (let k = 0; k < b; k++) {
        const p = probabilities[b * r + k];
        row[c + k] = (deterministic ? p >= 0.5 : randomF32(rngs[r]) < p) ? 1.0 : 0.0;
      }
      out.push(row);
    }
    return out;
  }
}

/** An action value clipped to [-1, 1], NaN as 0 (`from_policy_row` of both games). */
export const clipAction = (v) => (Number.isNaN(v) ? 0.0 : Math.min(Math.max(v, -1.0), 1.0));

/**
 * Plays `trials` runs of a course as `arlpcg verify --seed SEED --trials N` does: run i resets
 * with SEED + i and draws its actions from a ChaCha8 stream seeded SEED + i. The runs go side
 * by side (`pool` at a time, one batched graph run per decision), which changes no run.
 * `solver.act(rows, count, rngs, {deterministic})` gives the game's actions.
 * @returns {Promise<{results: object[], timing: {decisions: number, ms: number, networkMs: number}}>}
 */
export async function playRuns(solver, course, observationSize, { trials = 100, seed = 0, pool = 32, deterministic = false, onDecision = null } = {}) {
  const n = observationSize;
  const results = new Array(trials);
  const rows = new Float32Array(pool * n);
  let next = 0;
  let playing = [];
  let decisions = 0;
  let networkMs = 0;
  const started = performance.now();
  for (;;) {
    while (playing.length < pool && next < trials) {
      const s = seed + next;
      playing.push({ index: next, seed: s, run: course.reset(s), rng: ChaCha8Rng.seedFromU64(s) });
      next++;
    }
    if (playing.length === 0) break;
    playing.forEach((p, r) => course.observe(p.run, rows.subarray(r * n, (r + 1) * n)));
    const before = performance.now();
    const actions = await solver.act(rows, playing.length, playing.map((p) => p.rng), { deterministic });
    networkMs += performance.now() - before;
    decisions += playing.length;
    playing = playing.filter((p, r) => {
      if (onDecision) onDecision(p, rows.subarray(r * n, (r + 1) * n), actions[r]);
      const outcome = course.step(p.run, actions[r]);
      if (!outcome) return true;
      results[p.index] = { seed: p.seed, outcome, ...course.summary(p.run) };
      if (course.release) course.release(p.run);
      return false;
    });
  }
  // The time the runs took, and how much of it the graph (onnxruntime) and the draws took.
  return { results, timing: { decisions, ms: performance.now() - started, networkMs } };
}

/**
 * What a game's exported Solver shares: its graph, `act` (a batch of observation rows to the
 * game's actions, each row's draws from its own stream; `deterministic`: the means, as the
 * graph's outputs give them) and `play` (`playRuns` above; the timing of the last play in
 * `lastTiming`). A game's class adds `load` and `decode` (a raw action row to its action).
 */
export class GameSolver {
  constructor(network, observationSize) {
    this.network = network;
    this.observationSize = observationSize;
  }

  async act(rows, count, rngs, options = {}) {
    const raw = await this.network.act(rows, count, rngs, options);
    return raw.map((row) => this.decode(row));
  }

  async play(course, options = {}) {
    const { results, timing } = await playRuns(this, course, this.observationSize, options);
    this.lastTiming = timing;
    return results;
  }
}
