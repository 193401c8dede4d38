// Bundles the page (src/main.js and three.js from node_modules) into one minified ES module:
//   node build.mjs OUTFILE
// Called by viewer/CMakeLists.txt at build time. esbuild's JavaScript API finds its own native
// binary (the @esbuild/<platform> package the lock file pins), whatever npm did with install scripts.
import { buildSync } from 'esbuild';

const outfile = process.argv[2];
if (!outfile) {
  console.error('usage: node build.mjs OUTFILE');
  process.exit(2);
}
buildSync({
  entryPoints: [new URL('./src/main.js', import.meta.url).pathname],
  bundle: true,
  minify: true,
  format: 'esm',
  target: 'es2020',
  logLevel: 'warning',
  outfile,
});
