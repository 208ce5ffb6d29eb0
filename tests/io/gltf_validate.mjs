// The Khronos glTF validator (npm gltf-validator) over files named on the command line: one line
// per file, "valid" or "invalid", the error count and the path. External buffers and images are
// read from the file's own folder, as gdr reads them.
import { createRequire } from 'node:module';
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import { execSync } from 'node:child_process';

const root = process.env.GLTF_VALIDATOR_ROOT || execSync('npm root -g', { encoding: 'utf8' }).trim();
const require = createRequire(path.join(root, 'noop.js'));
const validator = require('gltf-validator');

for (const file of process.argv.slice(2)) {
    let verdict = 'invalid', errors = -1;
    try {
        const bytes = new Uint8Array(await readFile(file));
        const report = await validator.validateBytes(bytes, {
            uri: path.basename(file),
            maxIssues: 0,
            externalResourceFunction: (uri) =>
                readFile(path.join(path.dirname(file), decodeURIComponent(uri))).then((b) => new Uint8Array(b)),
        });
        errors = report.issues.numErrors;
        verdict = errors === 0 ? 'valid' : 'invalid';
    } catch (e) {
        verdict = 'invalid'; // the validator itself gave up on it
    }
    console.log(`${verdict}\t${errors}\t${file}`);
}
