// Runs the Khronos glTF-Validator (npm gltf-validator, installed by tests/gltf/install.sh) on
// each file named on the command line and prints one JSON line per file:
//   {"file": PATH, "errors": N, "codes": [ISSUE_CODE, ...], "first": "CODE at POINTER: message"}
// (codes of the issues of severity error only). An external resource (a buffer or image URI) is
// read as a plain loader would: percent-decoded and resolved against the file's folder; a URI
// with a scheme (http:, ftp:, file:, ...) is not fetched, so the validator reports it as an
// I/O error. A file the validator cannot start on (not glTF or GLB) or dies on counts as one
// error (code VALIDATOR_FAILED).
// Usage: node validate.js FILE...
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

const kSeverityError = 0;

function resourceLoader(folder) {
  return (uri) => new Promise((resolve, reject) => {
    if (/^[A-Za-z][A-Za-z0-9+.-]*:/.test(uri)) {
      reject(new Error('not fetched: ' + uri));
      return;
    }
    fs.readFile(path.resolve(folder, decodeURIComponent(uri)), (err, data) => {
      if (err) reject(err);
      else resolve(data);
    });
  });
}

// The validator can die of an exception thrown outside its promise (a JSON nested 100,000
// deep overflows its stack): that file then counts as refused by the validator, and the next
// file is validated as usual.
let crashed = null;
process.on('uncaughtException', (e) => {
  if (crashed) crashed(e);
  else throw e;
});

async function validateFile(file) {
  const bytes = new Uint8Array(fs.readFileSync(file));
  const crash = new Promise((resolve, reject) => { crashed = reject; });
  try {
    const report = await Promise.race([crash, validator.validateBytes(bytes, {
      uri: path.basename(file),
      maxIssues: 0,
      externalResourceFunction: resourceLoader(path.dirname(path.resolve(file))),
    })]);
    const errors = report.issues.messages.filter((m) => m.severity === kSeverityError);
    const first = errors.length ? `${errors[0].code} at ${errors[0].pointer || errors[0].offset}: ${errors[0].message}` : '';
    return {file, errors: report.issues.numErrors, codes: errors.map((m) => m.code), first};
  } catch (e) {
    return {file, errors: 1, codes: ['VALIDATOR_FAILED'], first: String(e).split('\n')[0]};
  }
}

(async () => {
  for (const file of process.argv.slice(2)) {
    console.log(JSON.stringify(await validateFile(file)));
  }
})();
