// Validates glTF/GLB files with the Khronos glTF validator (npm gltf-validator).
// Usage: node tools/validate_gltf.mjs FILE...  -> one JSON report per line
// ({file, errors, warnings, infos, messages}); exit status 1 when any file has errors.
import { readFileSync } from "node:fs";
import { createRequire } from "node:module";

const require = createRequire(import.meta.url);
const validator = require("gltf-validator");

let failed = false;
for (const file of process.argv.slice(2)) {
  const report = await validator.validateBytes(new Uint8Array(readFileSync(file)), {
    maxIssues: 50,
  });
  const i = report.issues;
  if (i.numErrors > 0) failed = true;
  console.log(
    JSON.stringify({
      file,
      errors: i.numErrors,
      warnings: i.numWarnings,
      infos: i.numInfos,
      messages: i.messages.map((m) => `${m.severity} ${m.code} ${m.pointer ?? ""} ${m.message}`),
    }),
  );
}
process.exit(failed ? 1 : 0);
