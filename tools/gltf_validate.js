// Validate glTF/GLB files with the Khronos glTF validator (npm "gltf-validator").
// Usage: node tools/gltf_validate.js FILE...   (NODE_PATH must reach gltf-validator)
// Prints one JSON line per file: {"file", "errors", "warnings", "infos", "hints", "messages"}.
// Exit status 0 when no file has errors or warnings, 1 otherwise, 2 on a usage or load failure.
"use strict";
const fs = require("fs");
const path = require("path");
let validator;
try {
  validator = require("gltf-validator");
} catch (e) {
  console.error("gltf-validator is not installed: npm install gltf-validator (and set NODE_PATH)");
  process.exit(2);
}
async function main(files) {
  if (!files.length) {
    console.error("usage: node gltf_validate.js FILE...");
    return 2;
  }
  let bad = 0;
  for (const file of files) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
      uri: path.basename(file),
      maxIssues: 100,
      externalResourceFunction: (uri) =>
        new Promise((resolve, reject) => {
          fs.readFile(path.join(path.dirname(file), decodeURIComponent(uri)), (err, data) =>
            err ? reject(err.toString()) : resolve(new Uint8Array(data)));
        }),
    });
    const i = report.issues;
    console.log(JSON.stringify({
      file, errors: i.numErrors, warnings: i.numWarnings, infos: i.numInfos, hints: i.numHints,
      messages: i.messages.filter((m) => m.severity <= 1).map((m) => `${m.code} ${m.pointer || ""}: ${m.message}`),
    }));
    if (i.numErrors || i.numWarnings) bad += 1;
  }
  return bad ? 1 : 0;
}
main(process.argv.slice(2)).then((code) => process.exit(code), (err) => {
  console.error(String(err));
  process.exit(2);
});
