const fs = require('fs');
const validator = require('gltf-validator');
const path = process.argv[2];
validator.validateBytes(new Uint8Array(fs.readFileSync(path)), { maxIssues: 50 })
  .then((r) => {
    const i = r.issues;
    console.log(`${r.validatorVersion}: errors ${i.numErrors}, warnings ${i.numWarnings}, infos ${i.numInfos}, hints ${i.numHints}`);
    for (const m of i.messages) console.log(`  [${m.severity}] ${m.code} ${m.pointer || ''}: ${m.message}`);
  })
  .catch((e) => { console.error('validation failed:', e); process.exit(1); });
