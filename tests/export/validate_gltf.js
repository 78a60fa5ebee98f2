// The Khronos glTF validator (npm gltf-validator) on each file named on the command line: prints one
// JSON report per file (the validator's own, without its timestamp), one per line. Exit 2 when the
// validator itself cannot run (no module, unreadable file). Module folder: $GLTF_VALIDATOR_MODULES.
"use strict";
const fs = require("fs");
const path = require("path");
const modules = process.env.GLTF_VALIDATOR_MODULES;
let validator;
try {
  validator = require(path.resolve(modules || ".", "gltf-validator"));
} catch (err) {
  console.error(`gltf-validator not found under ${modules}: ${err.message}`);
  process.exit(2);
}
(async () => {
  for (const file of process.argv.slice(2)) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
      uri: path.basename(file), writeTimestamp: false, maxIssues: 0,
    });
    report.path = file;
    console.log(JSON.stringify(report));
  }
})().catch((err) => { console.error(String(err)); process.exit(2); });
