// ctest viewer_page: plumb's own page in Debian's chromium, driven by npm's playwright-core, for a
// live `plumb run --serve` and for `plumb view` after a run (ground truth beside the estimate,
// error colouring, the run's map). Each time: wait until the page draws N poses, take a
// screenshot, and check its pixels: trajectory colours present in quantity, not a blank canvas.
// Screenshots: WORK_DIR/live.png, WORK_DIR/view.png.
// Usage: node page_check.js PLUMB WORK_DIR
'use strict';
const fs = require('fs');
const os = require('os');
const path = require('path');
const { spawnSync } = require('child_process');
const { chromium } = require('playwright-core');
const { startServing, check } = require('./plumb_process');
const { decodePng, countColours } = require('./png_pixels');

const BACKGROUND = [16, 18, 24];
// Flags from the brief for this closed machine: no network services, no first-run work, and a
// fresh profile every time.
const CHROMIUM_FLAGS = ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
                        '--disable-background-networking', '--disable-component-update', '--disable-sync'];

// The browser starts before plumb does: a live run lasts seconds, and chromium's start on a loaded
// 2-core CI machine can take as long, so a page opened only after the run started could find the
// server already gone (CI saw this as a 90 s wait for poses that never came).
async function withBrowser(body) {
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'plumb-viewer-chromium-'));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: '/usr/bin/chromium', headless: true, args: CHROMIUM_FLAGS, viewport: { width: 1000, height: 700 },
  });
  try {
    const page = await context.newPage();
    const errors = [];
    page.on('pageerror', (e) => errors.push(e.message));
    return await body(page, errors);
  } finally {
    await context.close();
    fs.rmSync(profile, { recursive: true, force: true });
  }
}

// Opens the served page, waits until it drew minPoses poses, takes a screenshot, returns its counters.
async function showPage(page, errors, port, minPoses, screenshot) {
  await page.goto(`http://127.0.0.1:${port}/`);
  await page.waitForFunction((n) => window.plumbViewer && window.plumbViewer.posesDrawn >= n, minPoses,
                             { timeout: 90000, polling: 200 });
  await page.waitForTimeout(1500);  // the follow-camera settles, a frame renders
  const stats = await page.evaluate(() => ({ ...window.plumbViewer, status: window.plumbViewer.status }));
  await page.screenshot({ path: screenshot });
  check(errors.length === 0, `page errors: ${errors.join('; ')}`);
  return stats;
}

function pixelsOf(file, named) {
  const result = countColours(decodePng(fs.readFileSync(file)), { background: BACKGROUND, ...named });
  check(result.counts.background < 0.995 * result.total, `${file} is a blank canvas`);
  check(result.distinct > 50, `${file} has only ${result.distinct} colours`);
  return result;
}

async function live(plumb, work) {
  // 300 frames paced at 30 Hz: a 10 s run, time enough for the page to connect while it lasts.
  const { stats, code, output } = await withBrowser(async (page, errors) => {
    const run = await startServing(plumb, ['run', '--dataset', 'paced:synth:textured:1:300', '--mode', 'fast',
                                           '--out', path.join(work, 'live.txt'), '--serve', '0']);
    let shown;
    try {
      shown = await showPage(page, errors, run.port, 60, path.join(work, 'live.png'));
    } catch (e) {
      run.child.kill('SIGTERM');
      throw e;
    }
    const { code } = await run.exited;
    return { stats: shown, code, output: run.output() };
  });
  check(code === 0, `plumb run exited ${code}:\n${output}`);
  const px = pixelsOf(path.join(work, 'live.png'), { output: [51, 204, 89], tracked: [255, 153, 25] });
  check(px.counts.output + px.counts.tracked > 300,
        `trajectory not drawn: ${px.counts.output} output and ${px.counts.tracked} tracked pixels`);
  check(stats.posesReceived >= 20 && stats.mapPoints > 0 && stats.status, `page counters ${JSON.stringify(stats)}`);
  return `live: ${stats.posesDrawn} poses drawn, ${stats.mapPoints} map points, ` +
         `${px.counts.output} output + ${px.counts.tracked} tracked trajectory pixels, ${px.distinct} colours`;
}

async function view(plumb, work) {
  const scene = path.join(work, 'scene');
  const run = (args) => {
    const r = spawnSync(plumb, args, { encoding: 'utf8' });
    check(r.status === 0, `plumb ${args.join(' ')} failed:\n${r.stdout}${r.stderr}`);
  };
  run(['synth', '--preset', 'textured', '--seed', '2', '--frames', '120', '--depth-noise', '--pixel-noise', '1', '--out', scene]);
  const est = path.join(work, 'estimate.txt'), map = path.join(work, 'run.map'), stats = path.join(work, 'run.json');
  run(['run', '--dataset', scene, '--out', est, '--save-map', map, '--stats', stats]);
  const { page, code, output } = await withBrowser(async (browserPage, errors) => {
    const served = await startServing(plumb, ['view', '--out', est, '--gt', path.join(scene, 'groundtruth.txt'),
                                              '--map', map, '--stats', stats, '--serve', '0']);
    let shown;
    try {
      shown = await showPage(browserPage, errors, served.port, 100, path.join(work, 'view.png'));
    } finally {
      served.child.kill('SIGTERM');
    }
    const { code } = await served.exited;
    return { page: shown, code, output: served.output() };
  });
  check(code === 0, `plumb view exited ${code} on SIGTERM:\n${output}`);
  // Error colours run green -> yellow -> red; ground truth is grey.
  const px = pixelsOf(path.join(work, 'view.png'), {
    low_error: [48, 191, 97], mid_error: [240, 209, 64], high_error: [240, 64, 64], ground_truth: [191, 191, 199],
  });
  const coloured = px.counts.low_error + px.counts.mid_error + px.counts.high_error;
  check(coloured > 300, `estimate not drawn in error colours: ${JSON.stringify(px.counts)}`);
  check(px.counts.ground_truth > 150, `ground truth not drawn: ${px.counts.ground_truth} grey pixels`);
  check(page.status && page.status.ate_rmse_m > 0, `status without ATE: ${JSON.stringify(page.status)}`);
  return `view: ${page.posesDrawn} poses drawn, ATE ${page.status.ate_rmse_m.toFixed(4)} m, ` +
         `${coloured} error-coloured + ${px.counts.ground_truth} ground-truth pixels, ${px.distinct} colours`;
}

async function main() {
  const [plumb, work] = process.argv.slice(2);
  fs.rmSync(work, { recursive: true, force: true });
  fs.mkdirSync(work, { recursive: true });
  console.log('viewer_page ' + (await live(plumb, work)));
  console.log('viewer_page ' + (await view(plumb, work)));
  console.log(`screenshots: ${path.join(work, 'live.png')} ${path.join(work, 'view.png')}`);
}

main().then(() => process.exit(0), (e) => {
  console.error('FAIL viewer_page:', e.message);
  process.exit(1);
});
