'use strict';
// The MAVLink acceptance test on a REAL run: `plumb run --dataset ... --mavlink udp:127.0.0.1:PORT
// --out traj.txt --output-delay 0` sends its stream here, node-mavlink (npm, a decoder written
// outside this project) splits, CRC-checks and decodes it, and every ODOMETRY message is compared
// with the trajectory file the same run wrote:
//   - with --output-delay 0 the file's pose of a frame is the pose tracking published (no local BA
//     refinement held back), so each ODOMETRY must equal its frame's line after the documented
//     frame change (docs/MAVLINK.md, default forward camera): position (tz, tx, ty), quaternion
//     (w, x, y, z) -> (w, z, x, y), to float32 precision (the file prints 9 significant digits);
//   - only message ids 0 and 331, no CRC error, consecutive sequence numbers (nothing lost);
//   - every frame with a pose is sent, except the ones whose velocity is not known yet (the first
//     pose, and the first after a reset or a lost stretch, docs/MAVLINK.md);
//   - time_usec = round(t * 1e6) of the frame's line.
// Usage: node decode_run_check.js --plumb BINARY --dataset SPEC --frames N --work DIR
const fs = require('fs');
const path = require('path');
const { spawn } = require('child_process');
const shared = require('./mavlink_capture');

const mav = shared.loadMavlink('mavlink_node_run');
const { common } = mav;
const args = shared.parseArgs(['plumb', 'dataset', 'work'],
  'node decode_run_check.js --plumb BINARY --dataset SPEC --frames N --work DIR');
const trajectoryPath = path.join(args.work, 'traj.txt');

let plumbOutput = '';
shared.captureFromSender({
  mav,
  senderName: 'plumb run',
  startSender: (port) => {
    const child = spawn(args.plumb, ['run', '--dataset', args.dataset, '--max-frames', args.frames || '250',
      '--mavlink', `udp:127.0.0.1:${port}`, '--out', trajectoryPath, '--output-delay', '0'],
    { stdio: ['ignore', 'pipe', 'inherit'] });
    child.stdout.on('data', (d) => { plumbOutput += d; });
    return child;
  },
  onSenderExit: () => process.stdout.write(plumbOutput),
  check,
});

// |decoded - value| within float32 rounding of the value plus the file's 9-digit rounding.
function closeAsFloat(decoded, value) {
  return Math.abs(decoded - value) <= Math.abs(value) * (Math.pow(2, -24) + 1e-8) + 1e-12;
}

function check(capture) {
  const { odometry, heartbeats, sequences, crcErrors } = capture;
  const failures = capture.failures.concat(shared.streamFailures(capture));
  const lines = fs.readFileSync(trajectoryPath, 'utf8').split('\n').filter((l) => l);
  const frames = [];  // {usec, valid, pose}
  for (const l of lines) {
    const f = l.trim().split(/\s+/);
    if (f[0] === '#') {
      if (f[2] === 'lost' || f[2] === 'dropped') frames.push({ usec: Math.round(Number(f[1]) * 1e6), valid: false });
      continue;
    }
    frames.push({ usec: Math.round(Number(f[0]) * 1e6), valid: true, v: f.slice(1, 8).map(Number) });
  }
  const byUsec = new Map(frames.map((fr, i) => [fr.usec, i]));
  for (let i = 1; i < sequences.length; i++) {
    if (sequences[i] !== ((sequences[i - 1] + 1) & 255)) { failures.push('sequence gap at packet ' + i); break; }
  }
  if (heartbeats.length < 1) failures.push('no HEARTBEAT');
  if (frames.length !== Number(args.frames || 250)) failures.push(`trajectory has ${frames.length} frames`);
  let maxPosErr = 0, maxQuatErr = 0, exactAsFloat = 0, compared = 0;
  const sent = new Set();
  let previousReset = null;
  const resets = new Set();
  for (let i = 0; i < odometry.length; i++) {
    const { header, data: d } = odometry[i];
    const k = byUsec.get(Number(d.timeUsec));
    const where = `message ${i} (time_usec ${d.timeUsec})`;
    if (k === undefined) { failures.push(where + ': no frame with that time in the trajectory'); continue; }
    if (sent.has(k)) failures.push(where + ': frame sent twice');
    sent.add(k);
    if (previousReset !== null && d.resetCounter !== previousReset) resets.add(k);
    previousReset = d.resetCounter;
    const fr = frames[k];
    if (!fr.valid) { failures.push(where + ': sent for a frame the trajectory marks lost'); continue; }
    failures.push(...shared.odometryHeaderFailures(common, header, d, where));
    if (!(d.quality >= 0 && d.quality <= 100)) failures.push(where + ': quality ' + d.quality);
    const [tx, ty, tz, qx, qy, qz, qw] = fr.v;
    const { pos, quat } = shared.frameChanged([tx, ty, tz], [qw, qx, qy, qz], d.q);
    const pd = [d.x, d.y, d.z];
    const expected = pos.concat(quat), decoded = pd.concat(Array.from(d.q));
    for (let j = 0; j < 7; j++) {
      compared++;
      if (Math.fround(expected[j]) === decoded[j]) exactAsFloat++;
      if (!closeAsFloat(decoded[j], expected[j])) failures.push(`${where}: field ${j} ${decoded[j]} != ${expected[j]}`);
      const err = Math.abs(decoded[j] - expected[j]);
      if (j < 3) maxPosErr = Math.max(maxPosErr, err); else maxQuatErr = Math.max(maxQuatErr, err);
    }
  }
  // Frames with a pose that were not sent: only where the velocity was not known yet.
  const unsent = [];
  for (let k = 0; k < frames.length; k++) {
    if (!frames[k].valid || sent.has(k)) continue;
    const firstAfterGap = k === 0 || !frames[k - 1].valid || resets.has(k + 1);
    if (!firstAfterGap) failures.push(`frame ${k} has a pose but was not sent`);
    unsent.push(k);
  }
  const valid = frames.filter((f) => f.valid).length;
  console.log(`mavlink_node_run: ${args.dataset}: trajectory ${frames.length} frames (${valid} with pose); ` +
    `node-mavlink decoded ${odometry.length} ODOMETRY + ${heartbeats.length} HEARTBEAT, ${crcErrors} CRC errors, ` +
    `${sequences.length} packets in sequence; not sent (velocity unknown): [${unsent.join(', ')}]; ` +
    `${exactAsFloat}/${compared} position/quaternion fields equal float32(file value); ` +
    `max |position - file| = ${maxPosErr.toExponential(2)} m, max |q - file| = ${maxQuatErr.toExponential(2)}`);
  if (odometry.length === 0) failures.push('nothing decoded');
  shared.finish(failures);
}
