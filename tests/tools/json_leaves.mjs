// Prints every leaf of a JSON document, one per line: its path (object keys and array indices
// joined by dots) and its value as JSON text. An empty object or array is a leaf ({} or []).
//   node json_leaves.mjs FILE.json
// JSON.parse is strict (no NaN or Infinity, no trailing comma, no comment, no bare word): a file it
// rejects makes this exit non-zero, with the parser's message. Used by the tests to read `plume
// check --json` back with a parser nobody on Plume wrote.
import fs from 'node:fs';

const file = process.argv[2];
if (!file) {
  console.error('usage: node json_leaves.mjs FILE.json');
  process.exit(2);
}
let document;
try {
  document = JSON.parse(fs.readFileSync(file, 'utf8'));
} catch (error) {
  console.error(`json_leaves: ${file}: ${error.message}`);
  process.exit(1);
}
const lines = [];
const walk = (value, path) => {
  if (value !== null && typeof value === 'object') {
    const entries = Array.isArray(value) ? value.map((item, index) => [String(index), item]) : Object.entries(value);
    if (entries.length === 0) lines.push(`${path} ${Array.isArray(value) ? '[]' : '{}'}`);
    for (const [key, item] of entries) walk(item, path ? `${path}.${key}` : key);
  } else {
    lines.push(`${path} ${JSON.stringify(value)}`);
  }
};
walk(document, '');
console.log(lines.join('\n'));
