// Validates glTF files with the Khronos glTF validator (npm package gltf-validator).
// Usage: node validate-gltf.mjs FILE.glb|FILE.gltf...   Exits 1 if any file has an error or a
// warning, printing the validator's messages for it; ends with a one-line summary.
import { readFile } from 'node:fs/promises';
import { dirname, join } from 'node:path';
import { createRequire } from 'node:module';

const require = createRequire(import.meta.url);
const validator = require('gltf-validator');

let bad = 0;
for (const file of process.argv.slice(2)) {
  const bytes = new Uint8Array(await readFile(file));
  const report = await validator.validateBytes(bytes, {
    uri: file,
    externalResourceFunction: (uri) =>
      readFile(join(dirname(file), decodeURIComponent(uri))).then((b) => new Uint8Array(b)),
  });
  const { numErrors, numWarnings, numInfos, numHints } = report.issues;
  if (numErrors > 0 || numWarnings > 0) {
    bad += 1;
    console.log(`${file}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos, ${numHints} hints`);
    for (const m of report.issues.messages) console.log(`  ${m.code} ${m.pointer ?? ''}: ${m.message}`);
  }
}
console.log(`${process.argv.length - 2 - bad} of ${process.argv.length - 2} glTF files valid (no errors, no warnings)`);
if (bad > 0) {
  console.error(`${bad} file(s) failed glTF validation`);
  process.exit(1);
}
