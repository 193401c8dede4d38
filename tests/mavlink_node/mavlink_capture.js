'use strict';
// What the two node-mavlink checks share: loading the decoder (or skipping), reading the
// arguments, capturing what a child process sends to a local UDP port and decoding it with
// node-mavlink (frames split, CRC-checked with its own CRC_EXTRA table, payloads decoded by its
// generated field tables), the documented frame change (docs/MAVLINK.md, default forward camera)
// and the final verdict.
const dgram = require('dgram');

// node-mavlink, or exit 77 (ctest: skipped) with a SKIP line naming the test.
function loadMavlink(testName) {
  try {
    return require('node-mavlink');
  } catch (e) {
    console.log(`SKIP ${testName}: cannot load node-mavlink (${e.message})`);
    process.exit(77);
  }
}

// --key value pairs; exits 2 with the usage line when a required key is missing.
function parseArgs(required, usage) {
  const args = {};
  for (let i = 2; i + 1 < process.argv.length; i += 2) args[process.argv[i].replace(/^--/, '')] = process.argv[i + 1];
  if (required.some((key) => !args[key])) {
    console.error('usage: ' + usage);
    process.exit(2);
  }
  return args;
}

// Binds a UDP socket on 127.0.0.1, starts the sender with startSender(port) (returns the child
// process), decodes everything it sends and, 500 ms after it exits with code 0, calls
// check(capture) with capture = { odometry, heartbeats ({header, data} each), sequences (every
// packet's seq), crcErrors, invalidPackets, failures (unknown or unexpected message ids) }.
// onSenderExit() runs first when given. A non-zero exit fails the test: "<senderName> failed".
function captureFromSender({ mav, senderName, startSender, onSenderExit, check }) {
  const { MavLinkPacketSplitter, MavLinkPacketParser, minimal, common } = mav;
  const registry = { ...minimal.REGISTRY, ...common.REGISTRY };
  const capture = { odometry: [], heartbeats: [], sequences: [], crcErrors: 0, invalidPackets: 0, failures: [] };
  const splitter = new MavLinkPacketSplitter({}, { onCrcError: () => { capture.crcErrors++; } });
  const parser = splitter.pipe(new MavLinkPacketParser());
  parser.on('data', (packet) => {
    capture.sequences.push(packet.header.seq);
    const clazz = registry[packet.header.msgid];
    if (!clazz) { capture.failures.push('unknown msgid ' + packet.header.msgid); return; }
    const data = packet.protocol.data(packet.payload, clazz);
    if (packet.header.msgid === 331) capture.odometry.push({ header: packet.header, data });
    else if (packet.header.msgid === 0) capture.heartbeats.push({ header: packet.header, data });
    else capture.failures.push('unexpected msgid ' + packet.header.msgid);
  });
  const socket = dgram.createSocket('udp4');
  socket.on('message', (msg) => splitter.write(msg));
  socket.bind(0, '127.0.0.1', () => {
    const child = startSender(socket.address().port);
    child.on('exit', (code) => {
      if (onSenderExit) onSenderExit();
      if (code !== 0) { console.error(`${senderName} failed with exit code ${code}`); process.exit(1); }
      setTimeout(() => {
        socket.close();
        splitter.end();
        setImmediate(() => {
          capture.invalidPackets = splitter.invalidPackages;
          check(capture);
        });
      }, 500);
    });
  });
}

// Problems common to every capture: CRC errors, invalid packets, no HEARTBEAT.
function streamFailures(capture) {
  const failures = [];
  if (capture.crcErrors) failures.push(capture.crcErrors + ' CRC errors');
  if (capture.invalidPackets) failures.push(capture.invalidPackets + ' invalid packets');
  return failures;
}

// Header and fixed fields every ODOMETRY message carries (sysid 1, compid 197, FRD frames, VISION).
function odometryHeaderFailures(common, header, d, where) {
  const failures = [];
  if (header.sysid !== 1 || header.compid !== 197) failures.push(where + ': sysid/compid');
  if (d.frameId !== common.MavFrame.LOCAL_FRD || d.childFrameId !== common.MavFrame.BODY_FRD) failures.push(where + ': frames');
  if (d.estimatorType !== common.MavEstimatorType.VISION) failures.push(where + ': estimator_type');
  return failures;
}

// The ODOMETRY position and quaternion (w, x, y, z) of a camera pose T_world_cam (t, q) after the
// documented frame change: position (tz, tx, ty), quaternion (w, x, y, z) -> (w, z, x, y), with the
// quaternion's sign chosen to match the decoded one (q and -q are the same rotation).
function frameChanged([tx, ty, tz], [qw, qx, qy, qz], decodedQ) {
  let quat = [qw, qz, qx, qy];
  if (quat[0] * decodedQ[0] + quat[1] * decodedQ[1] + quat[2] * decodedQ[2] + quat[3] * decodedQ[3] < 0) {
    quat = quat.map((v) => -v);
  }
  return { pos: [tz, tx, ty], quat };
}

// Prints the first problems and exits 1, or exits 0 when there are none.
function finish(failures) {
  if (failures.length) {
    console.log('FAILED: ' + failures.length + ' problems, first: ' + failures.slice(0, 10).join('; '));
    process.exit(1);
  }
  process.exit(0);
}

module.exports = { loadMavlink, parseArgs, captureFromSender, streamFailures, odometryHeaderFailures, frameChanged, finish };
