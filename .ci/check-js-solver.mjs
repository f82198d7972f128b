// Checks the JS Solvers against arlpcg itself: the exported Solver of a game playing levels in
// rapier.js (@dimforge/rapier3d-compat, pinned in .ci/package.json) under onnxruntime-node,
// against `arlpcg verify` playing the same levels in rapier3d. `--game=platform` (the default):
// web/platform-solver.mjs; `--game=racing`: web/racing-solver.mjs.
//
// 1. Exports policies/GAME/solver.safetensors (`arlpcg export-policy`) and checks the port on
//    its golden episode: every observation recomputed from the recorded state within 1e-5; one
//    decision stepped from each recorded state with the recorded action, against the next
//    recorded state (how many land within 1e-6 m, and the farthest, are printed); and the
//    episode replayed from its reset with the graph's deterministic actions (the position's
//    largest distance from the recorded one and the outcome are printed; the outcome must
//    match, and for platform the number of decisions too).
// 2. Has `arlpcg generate` build SEEDS levels of the game at each λ in --aux (the shipped
//    Generator; λ = -1 hard, +1 easy; racing: among --obstacles=N obstacles, 0 by default as
//    in levels/racing/), runs `arlpcg verify --json --threads 1 --trials N --seed 0` on them and
//    plays each level N times in the module with the same seeds (run i resets with seed i and
//    draws its actions from a stream seeded i, as verify does).
// 3. Prints each level's two success ratios (and how the other runs ended), the overall
//    success ratios, the milliseconds per decision and the time it took; exits 1 when the
//    overall ratios are more than --bar apart (0.05 by default) or the golden episode is not
//    reproduced.
//
//   node .ci/check-js-solver.mjs ARLPCG_BINARY [--game=platform|racing] [--seeds=5]
//       [--aux=-1,-0.5,0,1] [--trials=20] [--obstacles=0] [--bar=0.05] [--keep=DIR]

import { execFileSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { fileURLToPath } from "node:url";
import * as ort from "onnxruntime-node";
import RAPIER from "@dimforge/rapier3d-compat";
import { PlatformCourse, PlatformSolver, parsePlatformLevel } from "../web/platform-solver.mjs";
import { RacingCourse, RacingSolver, parseRacingLevel } from "../web/racing-solver.mjs";

const started = performance.now();
const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "..");
const args = process.argv.slice(2);
const flag = (name) => args.find((a) => a.startsWith(`--${name}=`))?.split("=")[1];
const [binaryArg] = args.filter((a) => !a.startsWith("--"));
if (!binaryArg) {
  console.error(
    "usage: node .ci/check-js-solver.mjs ARLPCG_BINARY [--game=platform|racing] [--seeds=5] [--aux=-1,-0.5,0,1] [--trials=20] [--obstacles=0] [--bar=0.05] [--keep=DIR]",
  );
  process.exit(2);
}
const binary = path.resolve(binaryArg);
const SEEDS = Number(flag("seeds") ?? 5);
const AUXES = (flag("aux") ?? "-1,-0.5,0,1").split(",").map(Number);
const TRIALS = Number(flag("trials") ?? 20);
const BAR = Number(flag("bar") ?? 0.05);
const GAME = flag("game") ?? "platform";
const OBSTACLES = Number(flag("obstacles") ?? 0);
// What differs between the games: the module, the golden state's position, how runs fail.
const GAMES = {
  platform: {
    Solver: PlatformSolver,
    Course: PlatformCourse,
    parse: parsePlatformLevel,
    observationSize: 40,
    position: (state) => state.feet,
    sameSteps: true,
    failures: [
      ["fell", "Fell", "fell"],
      ["timed out", "TimedOut", "timed_out"],
    ],
  },
  racing: {
    Solver: RacingSolver,
    Course: RacingCourse,
    parse: parseRacingLevel,
    observationSize: 47,
    position: (state) => state.position,
    // A racing episode runs ~600 decisions through the chassis's chaotic contacts with the road:
    // the replay ends alike, not on the same decision (docs/engines.md).
    sameSteps: false,
    failures: [
      ["off road", "OffRoad", "off_road"],
      ["flipped", "Flipped", "flipped"],
      ["timed out", "TimedOut", "timed_out"],
    ],
  },
};
const game = GAMES[GAME];
if (!game) throw new Error(`--game=${GAME}: platform or racing`);
if (OBSTACLES && GAME !== "racing") throw new Error("--obstacles is racing's");
// Observations recomputed from a golden episode's state: the port kit's bar (docs/engines.md).
const OBSERVATION_BAR = 1e-5;

const dir = flag("keep") ? path.resolve(flag("keep")) : fs.mkdtempSync(path.join(os.tmpdir(), "arlpcg-js-solver-"));
fs.mkdirSync(dir, { recursive: true });
const policy = path.join(root, `policies/${GAME}/solver.safetensors`);
const arlpcg = (...a) => execFileSync(binary, a, { cwd: root, encoding: "utf8", maxBuffer: 1 << 26 });

await RAPIER.init();
const onnxPath = path.join(dir, "solver.onnx");
arlpcg("export-policy", policy, "--out", onnxPath, "--force");
const sidecar = JSON.parse(fs.readFileSync(`${onnxPath}.json`, "utf8"));
const solver = await game.Solver.load(ort, new Uint8Array(fs.readFileSync(onnxPath)), sidecar, {
  sessionOptions: { intraOpNumThreads: 1, interOpNumThreads: 1 },
});
let failed = false;

// 1. The golden episode.
{
  const golden = JSON.parse(fs.readFileSync(`${onnxPath}.golden.json`, "utf8"));
  const course = new game.Course(RAPIER, game.parse(golden.level));
  const observation = new Float32Array(solver.observationSize);
  let worst = 0;
  golden.frames.forEach((frame, i) => {
    const run = course.runFromState(frame.state, i);
    course.observe(run, observation);
    frame.observation.forEach((want, k) => (worst = Math.max(worst, Math.abs(observation[k] - want))));
    course.release?.(run);
  });
  // One decision from each recorded state with the recorded action (the golden's actions are
  // the graph's deterministic ones, clipped), against the next recorded state.
  const stepped = [];
  for (let i = 0; i + 1 < golden.frames.length; i++) {
    const run = course.runFromState(golden.frames[i].state, i);
    course.step(run, solver.decode(golden.frames[i].action));
    const want = game.position(golden.frames[i + 1].state);
    stepped.push(Math.hypot(...course.position(run).map((v, k) => v - want[k])));
    course.release?.(run);
  }
  // Replayed from the reset, deterministically.
  let feetOff = 0;
  const frames = [];
  const [replayed] = await solver.play(course, {
    trials: 1,
    seed: golden.run_seed,
    deterministic: true,
    onDecision: (p) => frames.push(course.position(p.run).slice()),
  });
  frames.forEach((position, i) => {
    const want = golden.frames[i] && game.position(golden.frames[i].state);
    if (want) feetOff = Math.max(feetOff, Math.hypot(...position.map((v, k) => v - want[k])));
  });
  course.free();
  const same = replayed.outcome === golden.outcome && (!game.sameSteps || replayed.steps === golden.frames.length);
  console.log(
    `golden episode: observations from the recorded state within ${worst.toExponential(2)} (bar ${OBSERVATION_BAR}); ` +
      `one decision from each recorded state: ${stepped.filter((d) => d <= 1e-6).length} of ${stepped.length} within 1e-6 m ` +
      `of the next recorded state, the farthest ${Math.max(...stepped).toExponential(2)} m; ` +
      `replayed: ${replayed.outcome} in ${replayed.steps} decisions (recorded: ${golden.outcome} in ${golden.frames.length}), ` +
      `at most ${(feetOff * 1000).toFixed(2)} mm from the recorded positions`,
  );
  if (!(worst <= OBSERVATION_BAR) || !same) failed = true;
}

// 2. Levels, verify and the module.
const levelsDir = path.join(dir, "levels");
fs.rmSync(levelsDir, { recursive: true, force: true });
for (const aux of AUXES) {
  const obstacles = GAME === "racing" && OBSTACLES ? ["--obstacles", String(OBSTACLES)] : [];
  arlpcg("generate", "--game", GAME, "--policies", `policies/${GAME}`, `--aux=${aux}`, "--seed", "0", "--count", String(SEEDS), ...obstacles, "--out", levelsDir);
}
const files = fs.readdirSync(levelsDir).filter((f) => f.endsWith(".yaml")).sort().map((f) => path.join(levelsDir, f));
const verifyStarted = performance.now();
const verified = new Map(
  arlpcg("verify", "--json", "--threads", "1", "--trials", String(TRIALS), "--seed", "0", "--solver", "policy", "--policy", policy, ...files)
    .trim()
    .split("\n")
    .map((line) => JSON.parse(line))
    .map((v) => [path.resolve(root, v.level), v]),
);
const verifyMs = performance.now() - verifyStarted;

let rustSuccesses = 0;
let jsSuccesses = 0;
let runs = 0;
let decisions = 0;
let playMs = 0;
let networkMs = 0;
const gaps = [];
console.log(
  `${files.length} ${GAME} levels × ${TRIALS} runs (λ ${AUXES.join(", ")}; seeds 0-${SEEDS - 1}` +
    `${GAME === "racing" ? `; ${OBSTACLES} obstacles` : ""}); success verify → JS (and how runs failed):`,
);
for (const file of files) {
  const v = verified.get(file);
  if (!v) throw new Error(`verify gave no line for ${file}`);
  const course = new game.Course(RAPIER, game.parse(fs.readFileSync(file, "utf8")));
  const results = await solver.play(course, { trials: TRIALS, seed: 0 });
  course.free();
  decisions += solver.lastTiming.decisions;
  playMs += solver.lastTiming.ms;
  networkMs += solver.lastTiming.networkMs;
  const js = results.filter((r) => r.outcome === "Success").length;
  rustSuccesses += v.successes;
  jsSuccesses += js;
  runs += TRIALS;
  gaps.push(js / TRIALS - v.success_ratio);
  const failures = game.failures.map(([words, outcome, key]) => `${words} ${v[key]} → ${results.filter((r) => r.outcome === outcome).length}`);
  console.log(`  ${path.basename(file).padEnd(30)} ${v.success_ratio.toFixed(2)} → ${(js / TRIALS).toFixed(2)}   (${failures.join(", ")})`);
}
const rust = rustSuccesses / runs;
const js = jsSuccesses / runs;
const gap = Math.abs(js - rust);
const sorted = gaps.map(Math.abs).sort((a, b) => a - b);
console.log(
  `overall: verify ${rust.toFixed(4)}, JS ${js.toFixed(4)} over ${runs} runs each: |JS - verify| = ${gap.toFixed(4)} (bar ${BAR}); ` +
    `per level |gap| median ${sorted[sorted.length >> 1].toFixed(2)}, largest ${sorted[sorted.length - 1].toFixed(2)}, ` +
    `${gaps.filter((g) => g === 0).length} of ${files.length} levels equal`,
);
console.log(
  `JS: ${decisions} decisions in ${(playMs / 1000).toFixed(1)} s, ${(playMs / decisions).toFixed(3)} ms per decision ` +
    `(onnxruntime-node ${ort.env?.versions?.common ?? "?"}, batch ≤ 32 runs, ${((networkMs / playMs) * 100).toFixed(0)}% in the graph and the draws); ` +
    `verify ${(verifyMs / 1000).toFixed(1)} s; rapier.js ${RAPIER.version()}; all ${((performance.now() - started) / 1000).toFixed(1)} s`,
);
if (gap > BAR) failed = true;
if (!flag("keep")) fs.rmSync(dir, { recursive: true, force: true });
process.exit(failed ? 1 : 0);
