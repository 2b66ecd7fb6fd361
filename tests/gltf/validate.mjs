// Validates .glb / .gltf files with the Khronos glTF-Validator (npm package gltf-validator).
// Usage: node validate.mjs FILE... ; prints each report's issues and a summary line per file,
// exits 1 if any file has an error (or cannot be read), 0 otherwise. Warnings and infos are
// printed but do not fail.
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import validator from 'gltf-validator';

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error('usage: node validate.mjs FILE.glb|FILE.gltf ...');
  process.exit(2);
}
let failed = false;
for (const file of files) {
  try {
    const bytes = new Uint8Array(await readFile(file));
    const report = await validator.validateBytes(bytes, {
      uri: path.basename(file),
      maxIssues: 100,
      externalResourceFunction: (uri) =>
        readFile(path.resolve(path.dirname(file), decodeURIComponent(uri))).then(
          (b) => new Uint8Array(b)),
    });
    const s = report.issues;
    for (const m of s.messages) {
      console.log(`  ${['error', 'warning', 'info', 'hint'][m.severity]} ${m.code} ${m.pointer ?? ''}: ${m.message}`);
    }
    console.log(`${file}: errors=${s.numErrors} warnings=${s.numWarnings} infos=${s.numInfos} ` +
                `hints=${s.numHints} (gltf-validator ${report.validatorVersion})`);
    if (s.numErrors > 0) failed = true;
  } catch (e) {
    console.log(`${file}: cannot be validated: ${e && e.message ? e.message : e}`);
    failed = true;
  }
}
process.exit(failed ? 1 : 0);
