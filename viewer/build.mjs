// Bundles the viewer (src/main.js and the three.js it imports) into one minified classic script,
// the file plume embeds and inlines in every page: node build.mjs OUT.js
import * as esbuild from 'esbuild';
import { fileURLToPath } from 'node:url';

const out = process.argv[2];
if (!out) {
  console.error('usage: node build.mjs OUT.js');
  process.exit(2);
}
await esbuild.build({
  entryPoints: [fileURLToPath(new URL('src/main.js', import.meta.url))],
  outfile: out,
  bundle: true,
  minify: true,
  format: 'iife',
  target: 'es2020',
  charset: 'utf8',
  legalComments: 'eof',
  loader: { '.css': 'text' },
  logLevel: 'warning',
});
