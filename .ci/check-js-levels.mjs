// Checks web/levels.mjs against arlpcg itself: exports the shipped platform Generator to ONNX,
// checks web/rng.mjs against the Rust crates' own draws (web/test/rng-vectors.json), has
// `arlpcg generate` build SEEDS levels at each λ in {-1, 0, 1}, rebuilds each from its seed and
// λ with the module under node (onnxruntime-node), and compares the goal, the start heading,
// the number of blocks and every block's distance, angle, size and height within the file's
// rounding (1e-3). Prints each mismatch and the milliseconds per level; exits 1 on any mismatch
// (or, with --min-exact and --drift, beyond those bars; below).
//
// With --plain the network runs in plain JavaScript (web/network.mjs), from the Generator's
// numbers (`export-policy --out G.json`, what `arlpcg view` serves its page): no onnxruntime.
//
// With --browser=CHROMIUM the module runs in a page of headless Chromium (driven by
// puppeteer-core) on onnxruntime-web's WebAssembly build, served with the module from memory:
// the page asks nothing of the network.
//
//   node .ci/check-js-levels.mjs ARLPCG_BINARY [SEEDS (100)] [FIRST_SEED (0)] [--aux=-1,0,1]
//       [--min-exact=N --drift=D] [--ort=MODULE | --browser=CHROMIUM | --plain] [--game=racing --obstacles=N]

import { execFileSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";
import { PlatformGenerator } from "../web/levels.mjs";
import { PlainNetwork } from "../web/network.mjs";
import { RacingGenerator } from "../web/racing.mjs";
import { ChaCha8Rng } from "../web/rng.mjs";

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "..");
const args = process.argv.slice(2);
const flag = (name) => args.find((a) => a.startsWith(`--${name}=`))?.split("=")[1];
const [binary, seedsArg = "100", firstArg = "0"] = args.filter((a) => !a.startsWith("--"));
if (!binary) {
  console.error("usage: node .ci/check-js-levels.mjs ARLPCG_BINARY [SEEDS] [FIRST_SEED] [--game=racing --obstacles=N] [--aux=-1,0,1] [--min-exact=N --drift=D] [--ort=MODULE]");
  process.exit(2);
}
const seeds = Number(seedsArg);
const first = Number(firstArg);
// The file's rounding (1 mm, 0.001°), with room for the decimal's own rounding.
const TOLERANCE = 1e-3 + 1e-9;
// By default every value of every level must be within the file's rounding. The network's
// float32 sums differ between onnxruntime (MLAS) and arlpcg (candle's gemm): 4e-7 on the
// platform Generator's golden episode. A block's angle takes the turn action times 180°,
// quantized twice, so it can land a thousandth or two of a degree off, and the blocks after it
// observe that and drift a little. `--min-exact=N` passes when at least N levels are within the
// rounding in every value and every other level within `--drift=D` (degrees or metres) in every
// block value; the goal, the start and the number of blocks are always held to the rounding
// (and a racing level's obstacles).
// The runtime: onnxruntime-node (pinned in .ci/package.json) unless `--ort=` names another
// module (a path to onnxruntime-web's ESM entry, say: the same module runs in a page).
const browserPath = flag("browser");
const plain = args.includes("--plain");
const ortModule = browserPath
  ? "onnxruntime-web in headless Chromium"
  : plain
    ? "web/network.mjs, no onnxruntime"
    : flag("ort") ?? "onnxruntime-node";
const ort = browserPath || plain ? null : await import(ortModule.startsWith("/") ? pathToFileURL(ortModule).href : ortModule);
if (ort?.env?.wasm) ort.env.wasm.numThreads = 1;
// The game (`--game=racing`: web/racing.mjs and the racing Generator), and for racing the
// obstacles drawn from each seed (`--obstacles=N`, generate's flag).
const GAME = flag("game") ?? "platform";
const OBSTACLES = Number(flag("obstacles") ?? 0);
const PIECES = GAME === "racing" ? "segments" : "blocks";
const FIELDS = GAME === "racing" ? ["length", "curve", "height"] : ["distance", "angle", "size", "height"];
const minExact = flag("min-exact") === undefined ? null : Number(flag("min-exact"));
const AUXES = (flag("aux") ?? "-1,0,1").split(",").map(Number);
const DRIFT = (flag("drift") === undefined ? 1e-3 : Number(flag("drift"))) + 1e-9;

// First the random streams alone, against the Rust crates' own draws (web/test/rng-vectors.json).
{
  const { vectors } = JSON.parse(fs.readFileSync(path.join(root, "web/test/rng-vectors.json"), "utf8"));
  const bits = new DataView(new ArrayBuffer(4));
  let draws = 0;
  let wrong = 0;
  const expect = (what, got, want) => {
    draws++;
    if (got !== want) {
      wrong++;
      if (wrong <= 10) console.log(`rng: ${what}: ${got} vs ${want}`);
    }
  };
  for (const v of vectors) {
    const rng = ChaCha8Rng.seedFromU64(BigInt(v.seed));
    v.u32.forEach((want, i) => expect(`seed ${v.seed} u32 ${i}`, rng.nextU32(), want));
    v.u64.forEach((want, i) => expect(`seed ${v.seed} u64 ${i}`, rng.nextU64().toString(), want));
    expect(`seed ${v.seed} range a`, rng.randomRange(-180.0, 180.0), v.a);
    expect(`seed ${v.seed} range b`, rng.randomRange(30.0, 70.0), v.b);
    v.normals.forEach((want, i) => {
      bits.setFloat32(0, rng.standardNormalF32(), true);
      expect(`seed ${v.seed} normal ${i}`, bits.getUint32(0, true), want);
    });
  }
  console.log(`rng: ${draws - wrong} of ${draws} draws equal to the Rust crates' bits`);
  if (wrong > 0) process.exit(1);
}

const arlpcg = (...args) => execFileSync(path.resolve(binary), args, { cwd: root, stdio: ["ignore", "pipe", "inherit"] });
const tmp = fs.mkdtempSync(path.join(os.tmpdir(), "js-levels-"));
const onnxPath = path.join(tmp, "generator.onnx");
arlpcg("export-policy", `policies/${GAME}/generator.safetensors`, "--out", onnxPath);
const sidecar = JSON.parse(fs.readFileSync(`${onnxPath}.json`, "utf8"));
const Generator = GAME === "racing" ? RacingGenerator : PlatformGenerator;
// `build(request)`: the level and the milliseconds it took, under node or in the page.
const { build, close } = browserPath
  ? await inPage(browserPath)
  : await (async () => {
    const generator = plain
      ? new Generator(PlainNetwork.fromKit(plainNumbers(), GAME))
      : await Generator.load(ort, fs.readFileSync(onnxPath), sidecar);
    return {
      build: async (request) => {
        const began = performance.now();
        const level = await generator.build(request);
        return { level, ms: performance.now() - began };
      },
      close: async () => {},
    };
  })();

/** The shipped Generator's numbers (`export-policy --out G.json`, as `arlpcg view` serves them). */
function plainNumbers() {
  const file = path.join(tmp, "generator.json");
  arlpcg("export-policy", `policies/${GAME}/generator.safetensors`, "--out", file);
  return JSON.parse(fs.readFileSync(file, "utf8"));
}

/** The module in a page of headless Chromium, on onnxruntime-web (one WebAssembly thread). */
async function inPage(chromium) {
  const { default: puppeteer } = await import("puppeteer-core");
  const ortDist = path.join(root, ".ci/node_modules/onnxruntime-web/dist");
  const origin = "http://levels.test";
  const files = {
    "/generator.onnx": [fs.readFileSync(onnxPath), "application/octet-stream"],
    "/generator.onnx.json": [JSON.stringify(sidecar), "application/json"],
    "/": ['<!doctype html><title>web/levels.mjs</title><link rel="icon" href="data:,">', "text/html"],
  };
  const served = (url) => {
    const at = new URL(url).pathname;
    if (files[at]) return files[at];
    const [dir, kind] = at.startsWith("/web/") ? [path.join(root, "web"), "/web/"] : [ortDist, "/ort/"];
    if (!at.startsWith(kind)) return null;
    const file = path.join(dir, at.slice(kind.length));
    if (!file.startsWith(dir) || !fs.existsSync(file)) return null;
    const type = file.endsWith(".wasm") ? "application/wasm" : "text/javascript";
    return [fs.readFileSync(file), type];
  };
  const browser = await puppeteer.launch({ executablePath: chromium, headless: true, args: ["--no-sandbox"] });
  const page = await browser.newPage();
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  await page.setRequestInterception(true);
  page.on("request", (request) => {
    const found = request.url().startsWith(origin) ? served(request.url()) : null;
    if (!found) {
      errors.push(`asked for ${request.url()}`);
      request.respond({ status: 404, body: "" });
      return;
    }
    request.respond({ status: 200, contentType: found[1], body: found[0], headers: { "Access-Control-Allow-Origin": "*" } });
  });
  await page.goto(`${origin}/`);
  await page.evaluate(async (game) => {
    const ort = await import("/ort/ort.wasm.min.mjs");
    ort.env.wasm.numThreads = 1;
    ort.env.wasm.wasmPaths = "/ort/";
    const { PlatformGenerator } = await import("/web/levels.mjs");
    const { RacingGenerator } = await import("/web/racing.mjs");
    const onnx = new Uint8Array(await (await fetch("/generator.onnx")).arrayBuffer());
    const sidecar = await (await fetch("/generator.onnx.json")).json();
    const Generator = game === "racing" ? RacingGenerator : PlatformGenerator;
    const generator = await Generator.load(ort, onnx, sidecar);
    window.buildLevel = async (request) => {
      const began = performance.now();
      const level = await generator.build(request);
      return { level, ms: performance.now() - began };
    };
  }, GAME);
  const version = await browser.version();
  console.log(`in ${version}: the module loaded onnxruntime-web and the Generator in a page`);
  return {
    build: async (request) => {
      const answer = await page.evaluate((r) => window.buildLevel(r), request);
      if (errors.length) throw new Error(errors.join("; "));
      return answer;
    },
    close: async () => {
      await Promise.race([browser.close(), new Promise((resolve) => setTimeout(resolve, 5000))]);
      browser.process()?.kill("SIGKILL");
    },
  };
}

/** An obstacle's numbers in the level file's order. */
function obstacleNumbers(o) {
  return o.kind === "box" ? [...o.position, ...o.size, o.heading] : [...o.position, o.radius, o.height];
}

/** The goal, start heading, obstacles' numbers and pieces of a level file (what is compared). */
function readLevel(text) {
  const lines = text.split("\n");
  const level = { seed: null, goal: [], heading: null, obstacles: [], pieces: [] };
  let section = null;
  for (const line of lines) {
    const top = line.match(/^([a-z_]+):\s*(.*)$/);
    if (top) {
      section = top[1];
      if (section === "seed") level.seed = Number(top[2]);
      continue;
    }
    if (section === "goal") {
      const m = line.match(/^- (\S+)$/);
      if (m) level.goal.push(Number(m[1]));
    } else if (section === "start") {
      const m = line.match(/^ {2}heading: (\S+)$/);
      if (m) level.heading = Number(m[1]);
    } else if (section === PIECES) {
      const m = line.match(/^(- | {2})([a-z]+): (\S+)$/);
      if (m && FIELDS.includes(m[2])) {
        if (m[1] === "- ") level.pieces.push({});
        level.pieces[level.pieces.length - 1][m[2]] = Number(m[3]);
      }
    } else if (section === "obstacles") {
      if (line.startsWith("- kind:")) level.obstacles.push([]);
      const m = line.match(/^ {2}(?:- |[a-z]+: )(-?[0-9.]+)$/);
      if (m) level.obstacles[level.obstacles.length - 1].push(Number(m[1]));
    }
  }
  return level;
}

let mismatches = 0;
let levels = 0;
let exact = 0;
let worstDrift = 0;
const drifted = [];
const times = [];
for (const aux of AUXES) {
  const out = path.join(tmp, `aux${aux}`);
  arlpcg(
    "generate", "--game", GAME, "--policies", `policies/${GAME}`, `--aux=${aux}`, "--seed",
    String(first), "--count", String(seeds), "--out", out, "--format", "yaml",
    ...(GAME === "racing" ? ["--obstacles", String(OBSTACLES)] : []),
  );
  const files = fs.readdirSync(out).filter((f) => f.endsWith(".yaml"));
  if (files.length !== seeds) {
    console.error(`λ = ${aux}: generate wrote ${files.length} levels, not ${seeds}`);
    mismatches++;
  }
  for (const file of files.sort()) {
    const want = readLevel(fs.readFileSync(path.join(out, file), "utf8"));
    let got;
    try {
      const built = await build({ seed: want.seed, aux, obstacles: OBSTACLES });
      got = built.level;
      times.push(built.ms);
    } catch (error) {
      console.log(`${file}: the module built no level: ${error.message}`);
      mismatches++;
      levels++;
      continue;
    }
    levels++;
    const problems = [];
    const near = (a, b) => Math.abs(a - b) <= TOLERANCE;
    want.goal.forEach((g, i) => near(g, got.goal[i]) || problems.push(`goal[${i}] ${g} vs ${got.goal[i]}`));
    if (!near(want.heading, got.start.heading)) problems.push(`start heading ${want.heading} vs ${got.start.heading}`);
    const gotObstacles = (got.obstacles ?? []).map(obstacleNumbers).flat();
    const wantObstacles = want.obstacles.flat();
    if (gotObstacles.length !== wantObstacles.length || wantObstacles.some((v, i) => !near(v, gotObstacles[i]))) {
      problems.push(`obstacles ${wantObstacles} vs ${gotObstacles}`);
    }
    const gotPieces = got[PIECES];
    if (want.pieces.length !== gotPieces.length) {
      problems.push(`${want.pieces.length} ${PIECES} vs ${gotPieces.length} (attempt ${got.attempt})`);
    }
    const n = Math.min(want.pieces.length, gotPieces.length);
    const offs = [];
    for (let i = 0; i < n; i++) {
      for (const key of FIELDS) {
        const off = Math.abs(want.pieces[i][key] - gotPieces[i][key]);
        if (off > TOLERANCE) offs.push({ off, text: `${PIECES} ${i} ${key} ${want.pieces[i][key]} vs ${gotPieces[i][key]}` });
      }
    }
    const drift = Math.max(0, ...offs.map((o) => o.off));
    if (problems.length === 0 && offs.length === 0) exact++;
    if (problems.length === 0 && offs.length > 0) {
      worstDrift = Math.max(worstDrift, drift);
      drifted.push(`${file}: ${offs.length} values beyond 1e-3, largest ${drift.toFixed(4)} (${offs[0].text}; ...)`);
    }
    if (minExact === null || drift > DRIFT) problems.push(...offs.slice(0, 6).map((o) => o.text));
    if (problems.length > 0) {
      mismatches++;
      console.log(`${file} (λ = ${aux}): ${problems.join("; ")}`);
    }
  }
}
await close();
fs.rmSync(tmp, { recursive: true, force: true });
times.sort((a, b) => a - b);
const mean = times.reduce((a, b) => a + b, 0) / Math.max(times.length, 1);
const median = times[Math.floor(times.length / 2)] ?? 0;
if (minExact !== null) for (const line of drifted) console.log(`drifted: ${line}`);
console.log(
  `js levels, ${GAME}${GAME === "racing" ? ` with ${OBSTACLES} obstacles` : ""} (${seeds} seeds from ${first} at λ = ${AUXES.join(", ")}): ${exact} of ${levels} levels rebuilt ` +
    `to every value arlpcg generate wrote within its rounding (1e-3); ${drifted.length} more ` +
    `with the same goal, start${GAME === "racing" ? ", obstacles" : ""} and number of ${PIECES}, their values at most ` +
    `${worstDrift.toFixed(4)} off; ${mismatches} failed the check; ` +
    `${mean.toFixed(2)} ms per level on average, median ${median.toFixed(2)}, slowest ` +
    `${(times[times.length - 1] ?? 0).toFixed(2)} (${ortModule})`,
);
const enough = minExact === null ? exact === levels : exact >= minExact;
if (!enough) console.log(`${exact} levels within the rounding in every value: fewer than ${minExact ?? levels}`);
process.exit(mismatches === 0 && enough && levels > 0 ? 0 : 1);
