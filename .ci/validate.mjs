#!/usr/bin/env node
// Runs the Khronos glTF-Validator over files and folders (recursively) in one process and prints
// one JSON line per .gltf/.glb file: {"file", "errors", "warnings", "codes"} (codes of errors).
//
//   node .ci/validate.mjs PATH...
//
// Exit status: 0 when every file was validated (whatever it contains), 2 on a usage or I/O error.
// The tests decide what counts as a failure.
import { readFile, readdir, stat } from 'node:fs/promises';
import path from 'node:path';
import * as validator from 'gltf-validator';

async function collect(p, out) {
  const s = await stat(p);
  if (s.isDirectory()) {
    for (const name of (await readdir(p)).sort()) await collect(path.join(p, name), out);
  } else if (/\.(gltf|glb)$/i.test(p)) {
    out.push(p);
  }
}

const args = process.argv.slice(2);
if (args.length === 0) {
  console.error('usage: node .ci/validate.mjs PATH...');
  process.exit(2);
}
const files = [];
for (const a of args) await collect(a, files);
for (const file of files) {
  const full = path.resolve(file);
  const report = await validator.validateBytes(new Uint8Array(await readFile(full)), {
    uri: path.basename(full),
    maxIssues: 0,
    writeTimestamp: false,
    externalResourceFunction: (uri) =>
      readFile(path.resolve(path.dirname(full), decodeURIComponent(uri))).then((b) => new Uint8Array(b)),
  });
  const codes = [...new Set(report.issues.messages.filter((m) => m.severity === 0).map((m) => m.code))];
  console.log(JSON.stringify({ file, errors: report.issues.numErrors, warnings: report.issues.numWarnings, codes }));
}
