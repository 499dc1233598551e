// Runs the Khronos glTF validator (npm package gltf-validator) on .glb files and prints one JSON
// object per file: {"file", "numErrors", "numWarnings", "numInfos", "numHints", "messages"}.
// Usage: node validate_glb.js <directory holding node_modules/gltf-validator> <file.glb>...
const fs = require('fs');
const path = require('path');
const validator = require(path.join(path.resolve(process.argv[2]), 'node_modules', 'gltf-validator'));

async function main() {
  for (const file of process.argv.slice(3)) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)));
    const issues = report.issues;
    console.log(JSON.stringify({
      file: file,
      numErrors: issues.numErrors,
      numWarnings: issues.numWarnings,
      numInfos: issues.numInfos,
      numHints: issues.numHints,
      messages: issues.messages.map((m) => `${m.code} ${m.pointer || ''}: ${m.message}`),
    }));
  }
}

main().catch((error) => {
  console.error(String(error));
  process.exit(1);
});
