// SPDX-License-Identifier: AGPL-3.0-or-later
// Runs the Khronos glTF-Validator (npm gltf-validator) on GLB files.
// usage: node validate_glb.js VALIDATOR_DIR FILE.glb [...]
//   VALIDATOR_DIR: the npm prefix holding node_modules/gltf-validator
//   (scripts/setup.sh installs it into BUILD/tools/gltf-validator).
// Prints one JSON object per file: {"file", "errors", "warnings", "infos",
// "hints", "messages": [{"severity", "code", "message", "pointer"}]} (messages:
// errors and warnings only). Exit 0 if no file has an error or a warning,
// 1 if one has, 2 if the validator cannot be loaded or a file read.
const fs = require('fs');
const path = require('path');
let validator;
try {
  validator = require(path.join(path.resolve(process.argv[2]), 'node_modules', 'gltf-validator'));
} catch (e) {
  console.error(`cannot load gltf-validator from ${process.argv[2]}: ${e.message}`);
  process.exit(2);
}
(async () => {
  let bad = 0;
  for (const file of process.argv.slice(3)) {
    let bytes;
    try {
      bytes = new Uint8Array(fs.readFileSync(file));
    } catch (e) {
      console.error(`cannot read ${file}: ${e.message}`);
      process.exit(2);
    }
    const report = await validator.validateBytes(bytes, {
      uri: file,
      maxIssues: 100,
      externalResourceFunction: (uri) => new Promise((resolve, reject) => {
        try {
          resolve(new Uint8Array(fs.readFileSync(path.resolve(path.dirname(file), decodeURIComponent(uri)))));
        } catch (e) {
          reject(e.toString());
        }
      }),
    });
    const i = report.issues;
    const messages = i.messages.filter((m) => m.severity <= 1).map((m) => ({
      severity: m.severity === 0 ? 'error' : 'warning', code: m.code, message: m.message, pointer: m.pointer || '',
    }));
    console.log(JSON.stringify({file, errors: i.numErrors, warnings: i.numWarnings, infos: i.numInfos,
                                hints: i.numHints, messages}));
    if (i.numErrors || i.numWarnings) bad = 1;
  }
  process.exit(bad);
})();
