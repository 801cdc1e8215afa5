// The scenario schema as an editor's validator sees it: ajv (draft 2020-12) in its default strict mode.
//   node ajv_check.mjs SCHEMA.json [FILE.json ...]
// Compiles the schema (strict mode refuses unknown keywords and formats), then validates each JSON file
// (a scenario converted from YAML); prints one JSON line: {compiled, error?, results: [{file, valid, errors}]}.
import Ajv2020Module from "ajv/dist/2020.js";
import { readFileSync } from "node:fs";

const Ajv2020 = Ajv2020Module.default ?? Ajv2020Module;
const [schemaPath, ...files] = process.argv.slice(2);
const out = { compiled: false, results: [] };
try {
  const ajv = new Ajv2020({ allErrors: true });
  const validate = ajv.compile(JSON.parse(readFileSync(schemaPath, "utf8")));
  out.compiled = true;
  for (const file of files) {
    const valid = validate(JSON.parse(readFileSync(file, "utf8")));
    out.results.push({ file, valid, errors: (validate.errors ?? []).slice(0, 5) });
  }
} catch (e) {
  out.error = String(e?.message ?? e);
}
process.stdout.write(JSON.stringify(out) + "\n");
