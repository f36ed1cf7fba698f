// Runs the Khronos glTF-Validator (installed beside this script by .ci/run) on every .glb
// given on the command line. Prints each message; exits non-zero when any file has an error
// or a warning, or cannot be read.
import { readFile } from 'node:fs/promises';
import { createRequire } from 'node:module';

const require = createRequire(import.meta.url);
const validator = require('gltf-validator');

let bad = 0;
for (const file of process.argv.slice(2)) {
  try {
    const bytes = new Uint8Array(await readFile(file));
    const report = await validator.validateBytes(bytes, { maxIssues: 100 });
    const { numErrors, numWarnings, numInfos, numHints } = report.issues;
    console.log(`${file}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos, ${numHints} hints`);
    for (const m of report.issues.messages) {
      console.log(`  [${['error', 'warning', 'info', 'hint'][m.severity]}] ${m.code} ${m.pointer ?? ''}: ${m.message}`);
    }
    if (numErrors > 0 || numWarnings > 0) bad += 1;
  } catch (e) {
    console.log(`${file}: cannot validate: ${e}`);
    bad += 1;
  }
}
if (process.argv.length <= 2) {
  console.log('no .glb files given');
  bad += 1;
}
const total = Math.max(process.argv.length - 2, 0);
console.log(`glTF-Validator: ${total - Math.min(bad, total)} passed, ${bad} failed`);
process.exit(bad > 0 ? 1 : 0);
