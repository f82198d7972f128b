// `arlpcg view` in a real browser (headless Chromium, driven by puppeteer-core): the page draws
// the level (not a blank canvas) and its certificate run within 2 s of opening, then the first
// trials of its verification played again (/runs.json), a new level
// written to the folder it follows changes the picture within 1 s, moving the page's λ slider
// shows each level rebuilt at the new λ by the shipped Generator within 1 s, built in the page
// itself (web/network.mjs; the page never asks the server for a rebuilt scene) and equal to
// the scene the server rebuilds (every box, mesh vertex and point within 1e-3), and the page's
// console has no errors.
// LEVEL_C, where given, is a level made for a profile, rebuilt in the page the same way.
// Usage: node .ci/check-view.mjs ARLPCG_BINARY CHROMIUM LEVEL_A LEVEL_B SCREENSHOT_DIR [LEVEL_C]
import { spawn } from "node:child_process";
import { copyFileSync, mkdtempSync, mkdirSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import puppeteer from "puppeteer-core";

const [binary, chromium, levelA, levelB, shots, levelC] = process.argv.slice(2);
const fail = (message) => { console.error(`check-view: ${message}`); failed = true; };
let failed = false;
const folder = mkdtempSync(join(tmpdir(), "arlpcg-view-"));
mkdirSync(shots, { recursive: true });
copyFileSync(levelA, join(folder, "a.yaml"));

const server = spawn(binary, ["view", folder], { stdio: ["ignore", "pipe", "inherit"] });
const address = await new Promise((resolve, reject) => {
  let seen = "";
  server.stdout.on("data", (chunk) => {
    seen += chunk;
    const found = seen.match(/http:\/\/[0-9.:]+\//);
    if (found) resolve(found[0]);
  });
  server.on("exit", (code) => reject(new Error(`arlpcg view exited with ${code}`)));
});

const browser = await puppeteer.launch({
  executablePath: chromium,
  headless: true,
  args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"],
});
const errors = [];
try {
  const page = await browser.newPage();
  await page.setViewport({ width: 1024, height: 640 });
  page.on("console", (message) => { if (message.type() === "error") errors.push(message.text()); });
  page.on("pageerror", (error) => errors.push(String(error)));
  // Offline: the page may ask only the server it came from.
  await page.setRequestInterception(true);
  const asked = [];
  page.on("request", (request) => {
    asked.push(request.url());
    if (request.url().startsWith(address)) request.continue();
    else { errors.push(`asked the network for ${request.url()}`); request.abort(); }
  });

  const opened = Date.now();
  await page.goto(address);
  await page.waitForFunction(() => Number(document.body.dataset.drawn) > 2000, { timeout: 2000 });
  const first = await page.evaluate(() => ({ ...document.body.dataset }));
  console.log(`first picture after ${Date.now() - opened} ms: ${first.drawn} pixels drawn`);
  await page.screenshot({ path: join(shots, "view-first.png") });
  if (!(Number(first.trail) > 10)) fail(`the certificate run is not drawn (${first.trail} points)`);
  // The first trials of its verification, played again by the server, drawn after the picture.
  await page.waitForFunction(() => Number(document.body.dataset.runs) > 0, { timeout: 5000 });
  const withRuns = await page.evaluate(() => ({ ...document.body.dataset, caption: document.getElementById("caption").textContent }));
  console.log(`${withRuns.runs} runs replayed ${Date.now() - opened} ms after the page opened: ${withRuns.drawn} pixels drawn (${withRuns.caption})`);
  await page.screenshot({ path: join(shots, "view-runs.png") });
  if (withRuns.runs !== "8" || !withRuns.caption.includes("8 runs of its verification replayed")) fail(`not 8 runs replayed: ${withRuns.runs}`);
  const afterA = await moveSlider(page, withRuns, "a");

  const written = Date.now();
  copyFileSync(levelB, join(folder, "b.yaml"));
  await page.waitForFunction((version) => document.body.dataset.version !== version, { timeout: 1000 }, first.version);
  await page.waitForFunction(() => Number(document.body.dataset.drawn) > 2000, { timeout: 1000 });
  const second = await page.evaluate(() => ({ ...document.body.dataset }));
  console.log(`new level shown ${Date.now() - written} ms after it was written: ${second.drawn} pixels drawn`);
  await page.screenshot({ path: join(shots, "view-second.png") });
  if (second.drawn === afterA.drawn) fail("the new level did not change the picture");
  const afterB = await moveSlider(page, second, "b");
  // A level made for a profile: the page builds it with the profile's rules the server measured.
  if (levelC) {
    const last = await page.evaluate(() => ({ ...document.body.dataset }));
    const written = Date.now();
    copyFileSync(levelC, join(folder, "c.yaml"));
    await page.waitForFunction((version) => document.body.dataset.version !== version, { timeout: 5000 }, last.version);
    console.log(`the profile's level shown ${Date.now() - written} ms after it was written`);
    const third = await page.evaluate(() => ({ ...document.body.dataset }));
    if (third.drawn === afterB.drawn) fail("the profile's level did not change the picture");
    // Its own λ (-1) last: the first move must change the level, and a level with no runs
    // drawn over it looks the same rebuilt at its own λ. The first move may wait for the
    // profile's rules (the page asks for them as the level is shown; measuring the character's
    // reach takes the server 1-2 s): 3 s.
    await moveSlider(page, third, "c", ["1", "-1"], 3000);
  }
  if (asked.some((url) => url.includes("/scene.json?aux"))) fail("the page asked the server for a rebuilt scene");
  if (first.errors || second.errors) fail(`the page reported errors: ${first.errors}${second.errors}`);
  if (errors.length) fail(`console errors: ${errors.join("; ")}`);
} catch (error) {
  fail(`${error.message}${errors.length ? ` (console: ${errors.join("; ")})` : ""}`);
} finally {
  server.kill();
  // Closing a headless Chromium can hang on some machines: give it 5 s.
  await Promise.race([browser.close(), new Promise((resolve) => setTimeout(resolve, 5000))]);
  browser.process()?.kill("SIGKILL");
}
/**
 * The λ slider: the shipped Generator rebuilds the level shown at λ = -1, then +1 (or `order`), in the page;
 * each picture changes, and the page's scene is the one the server rebuilds at that λ.
 */
async function moveSlider(page, before, name, order = ["-1", "1"], firstTimeout = 1000) {
  if (await page.evaluate(() => document.getElementById("slider").hidden)) fail(`${name}: no λ slider`);
  for (const aux of order) {
    const moved = Date.now();
    await page.evaluate((aux) => {
      const input = document.getElementById("aux");
      input.value = aux;
      input.dispatchEvent(new Event("input"));
    }, aux);
    const timeout = aux === order[0] ? firstTimeout : 1000;
    await page.waitForFunction((aux) => document.body.dataset.aux === aux, { timeout }, aux);
    const rebuilt = await page.evaluate(() => ({ ...document.body.dataset, caption: document.getElementById("caption").textContent }));
    console.log(`${name}: λ = ${aux} shown ${Date.now() - moved} ms after the slider moved, built by the ${rebuilt.rebuilt}: ${rebuilt.drawn} pixels drawn (${rebuilt.caption})`);
    await page.screenshot({ path: join(shots, `view-${name}-aux${aux}.png`) });
    if (rebuilt.rebuilt !== "page") fail(`${name}: λ = ${aux} was not built in the page (${rebuilt.caption})`);
    if (rebuilt.drawn === before.drawn) fail(`${name}: λ = ${aux} did not change the picture`);
    if (rebuilt.errors) fail(`${name}: the page reported errors: ${rebuilt.errors}`);
    const mine = await page.evaluate(() => window.viewScene);
    const server = (await (await fetch(`${address}scene.json?aux=${aux}`)).json()).scene;
    const off = sceneDifference(mine, server);
    console.log(`${name}: λ = ${aux}: the page's scene against the server's: ${off}`);
    if (off !== "equal") fail(`${name}: λ = ${aux}: the page's level is not the server's: ${off}`);
    before = rebuilt;
  }
  return before;
}

/** "equal" where every box, mesh and point of two scenes agree within 1e-3 (m, °), else the first difference. */
function sceneDifference(a, b) {
  if (a.pieces !== b.pieces) return `${a.pieces} pieces against ${b.pieces}`;
  const close = (x, y) => x.length === y.length && x.every((v, i) => Math.abs(v - y[i]) <= 1e-3);
  for (const [part, fields] of [["boxes", ["centre", "extents"]], ["meshes", ["positions", "indices"]], ["points", ["position"]]]) {
    if (a[part].length !== b[part].length) return `${a[part].length} ${part} against ${b[part].length}`;
    for (let i = 0; i < a[part].length; i++) {
      const [x, y] = [a[part][i], b[part][i]];
      if (x.name !== y.name) return `${part}[${i}] ${x.name} against ${y.name}`;
      for (const field of fields) if (!close(x[field], y[field])) return `${x.name}'s ${field} differ`;
      if (part !== "meshes" && Math.abs(x.heading - y.heading) > 1e-3) return `${x.name}'s heading ${x.heading} against ${y.heading}`;
      if (part === "points" && !close(x.size ?? [], y.size ?? [])) return `${x.name}'s size differ`;
    }
  }
  return "equal";
}

if (failed) process.exit(1);
console.log("check-view: ok");
process.exit(0);
