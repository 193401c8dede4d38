'use strict';
// Receives plumb's MAVLink stream over UDP and decodes it with node-mavlink (npm), a decoder
// written outside this project: frames are split and CRC-checked (with node-mavlink's own
// CRC_EXTRA table), payloads decoded by its generated field tables. Then every ODOMETRY message
// is compared with the sender's file:
//   - exactly (as float32) with the values the sender says it wrote;
//   - within float precision with the documented frame change (docs/MAVLINK.md) applied here,
//     independently, to the raw camera pose T_world_cam: default forward camera, so
//     position_local = (cam z, cam x, cam y) and quaternion (w, x, y, z) -> (w, z, x, y).
// Usage: node decode_check.js --sender BINARY --frames N --expected FILE
const fs = require('fs');
const { spawn } = require('child_process');
const shared = require('./mavlink_capture');

const mav = shared.loadMavlink('mavlink_node_decode');
const { common } = mav;
const args = shared.parseArgs(['sender', 'expected'], 'node decode_check.js --sender BINARY --frames N --expected FILE');

shared.captureFromSender({
  mav,
  senderName: 'sender',
  startSender: (port) => spawn(args.sender, ['--endpoint', `udp:127.0.0.1:${port}`, '--frames', args.frames || '250',
    '--rate-hz', '1000', '--expected', args.expected], { stdio: ['ignore', 'inherit', 'inherit'] }),
  check,
});

function sameFloat32(decoded, expectedText) {
  const e = Number(expectedText);
  if (Number.isNaN(e)) return Number.isNaN(decoded);
  return Math.fround(e) === decoded;
}

function check(capture) {
  const { odometry, heartbeats, crcErrors } = capture;
  const failures = capture.failures.concat(shared.streamFailures(capture));
  const lines = fs.readFileSync(args.expected, 'utf8').split('\n').filter((l) => l && !l.startsWith('#'));
  if (odometry.length !== lines.length) failures.push(`decoded ${odometry.length} ODOMETRY, sender wrote ${lines.length}`);
  if (heartbeats.length < 1) failures.push('no HEARTBEAT');
  for (const hb of heartbeats) {
    const d = hb.data;
    if (hb.header.compid !== 197 || d.type !== 18 || d.autopilot !== 8 || d.mavlinkVersion !== 3) {
      failures.push('bad HEARTBEAT ' + JSON.stringify({ compid: hb.header.compid, type: d.type, autopilot: d.autopilot }));
    }
  }
  let maxPosErr = 0, maxQuatErr = 0, exactFields = 0;
  const n = Math.min(lines.length, odometry.length);
  for (let i = 0; i < n; i++) {
    const f = lines[i].trim().split(/\s+/);
    const { header, data: d } = odometry[i];
    const where = `message ${i} (frame ${f[0]})`;
    failures.push(...shared.odometryHeaderFailures(common, header, d, where));
    if (header.payloadLength > 233) failures.push(where + ': payload length ' + header.payloadLength);
    if (String(d.timeUsec) !== f[8]) failures.push(`${where}: time_usec ${d.timeUsec} != ${f[8]}`);
    // Exact comparison with what the sender wrote.
    const decoded = [d.x, d.y, d.z, ...d.q, d.vx, d.vy, d.vz, d.rollspeed, d.pitchspeed, d.yawspeed];
    for (let j = 0; j < decoded.length; j++) {
      if (!sameFloat32(decoded[j], f[9 + j])) failures.push(`${where}: field ${j} ${decoded[j]} != ${f[9 + j]}`);
      else exactFields++;
    }
    if (d.resetCounter !== Number(f[22]) || d.quality !== Number(f[23])) failures.push(where + ': reset_counter/quality');
    for (let j = 0; j < 21; j++) {
      if (!sameFloat32(d.poseCovariance[j], f[24 + j])) failures.push(`${where}: pose_covariance[${j}]`);
      else exactFields++;
    }
    if (!Number.isNaN(d.velocityCovariance[0])) failures.push(where + ': velocity covariance should be unknown (NaN)');
    // Independent frame change from the raw camera pose.
    const [tx, ty, tz, qw, qx, qy, qz] = f.slice(1, 8).map(Number);
    const { pos, quat } = shared.frameChanged([tx, ty, tz], [qw, qx, qy, qz], d.q);
    const pd = [d.x, d.y, d.z];
    for (let j = 0; j < 3; j++) maxPosErr = Math.max(maxPosErr, Math.abs(pd[j] - pos[j]));
    for (let j = 0; j < 4; j++) maxQuatErr = Math.max(maxQuatErr, Math.abs(d.q[j] - quat[j]));
  }
  // float32 has a 24-bit mantissa: positions up to ~10 m carry <= ~5e-7 m rounding.
  if (maxPosErr > 1e-6) failures.push('position differs from the frame-changed trajectory by ' + maxPosErr);
  if (maxQuatErr > 2e-7) failures.push('quaternion differs from the frame-changed trajectory by ' + maxQuatErr);
  console.log(`mavlink_node_decode: node-mavlink decoded ${odometry.length} ODOMETRY + ${heartbeats.length} HEARTBEAT, ` +
    `${crcErrors} CRC errors; ${exactFields} float fields equal as float32; ` +
    `max |position - frame-changed trajectory| = ${maxPosErr.toExponential(2)} m, max |q diff| = ${maxQuatErr.toExponential(2)}`);
  shared.finish(failures);
}
