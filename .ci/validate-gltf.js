// Validates .glb files with the Khronos glTF-Validator (npm `gltf-validator`).
// Usage: node .ci/validate-gltf.js FILE.glb...
// Prints the issue counts and every message; exits 1 on any error (warnings are reported only).
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require(path.join(__dirname, 'node', 'node_modules', 'gltf-validator'));

async function main() {
  const files = process.argv.slice(2);
  if (files.length === 0) {
    console.error('usage: node .ci/validate-gltf.js FILE.glb...');
    process.exit(2);
  }
  let failed = false;
  for (const file of files) {
    const data = new Uint8Array(fs.readFileSync(file));
    const report = await validator.validateBytes(data, {
      uri: file,
      maxIssues: 0,
      externalResourceFunction: () => Promise.reject(new Error('no external resources expected')),
    });
    const i = report.issues;
    console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos, ${i.numHints} hints` +
      ` (${report.info ? report.info.animationCount + ' animation, ' + report.info.totalTriangleCount + ' triangles' : 'no info'})`);
    for (const m of i.messages) {
      const sev = ['error', 'warning', 'info', 'hint'][m.severity] || m.severity;
      console.log(`  ${sev} ${m.code} ${m.pointer || ''}: ${m.message}`);
    }
    if (i.numErrors > 0) failed = true;
  }
  process.exit(failed ? 1 : 0);
}

main().catch((e) => {
  console.error(`validate-gltf: ${e}`);
  process.exit(1);
});
