// Bundles entry.js (three.js's parts that report.html uses) into one minified classic
// script defining the global `FoldsynthThree`. `node build.mjs [OUTFILE]`.
import { buildSync } from 'esbuild';

buildSync({
  entryPoints: ['entry.js'],
  bundle: true,
  minify: true,
  format: 'iife',
  globalName: 'FoldsynthThree',
  target: 'es2020',
  legalComments: 'inline',
  outfile: process.argv[2] ?? 'three.bundle.min.js',
  logLevel: 'warning',
});
