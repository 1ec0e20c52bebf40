#!/usr/bin/env node
// Validates glTF 2.0 files with the Khronos glTF validator and prints one JSON line per
// file: {"file", "errors", "warnings", "infos", "hints", "messages": [the 20 most severe issues]}.
// Exits 1 if any file has an error, 2 on a usage or read error.
// Install once: `npm ci --prefix tools/gltf-validator`.
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

async function main(files) {
  if (files.length === 0) {
    console.error('usage: validate.js FILE.gltf|FILE.glb ...');
    process.exit(2);
  }
  let failed = false;
  for (const file of files) {
    const bytes = new Uint8Array(fs.readFileSync(file));
    const report = await validator.validateBytes(bytes, {
      uri: path.basename(file),
      maxIssues: 1000,
      externalResourceFunction: (uri) =>
        new Promise((resolve, reject) => {
          fs.readFile(path.resolve(path.dirname(file), decodeURIComponent(uri)), (err, data) =>
            err ? reject(err.toString()) : resolve(new Uint8Array(data)));
        }),
    });
    const i = report.issues;
    // The most severe first, so that the 20 shown include every error and warning there is room for.
    const messages = [...i.messages].sort((a, b) => a.severity - b.severity).slice(0, 20).map((m) => `${m.severity === 0 ? 'error' : m.severity === 1 ? 'warning' : m.severity === 2 ? 'info' : 'hint'} ${m.code} ${m.pointer || ''}: ${m.message}`);
    console.log(JSON.stringify({ file, errors: i.numErrors, warnings: i.numWarnings, infos: i.numInfos, hints: i.numHints, messages }));
    if (i.numErrors > 0) failed = true;
  }
  process.exit(failed ? 1 : 0);
}

main(process.argv.slice(2)).catch((e) => {
  console.error(String(e));
  process.exit(2);
});
