// ctest viewer_foxglove_client: Foxglove's own client library (npm @foxglove/ws-protocol, the one
// Foxglove and Lichtblick build on) subscribes to every channel of a real `plumb run --serve` on a
// synthetic scene and checks
//   - serverInfo, and the advertised channels: topics, Foxglove schema names, JSON encoding,
//     JSON Schemas that parse and name the fields the messages carry;
//   - /plumb/output_pose: every pose equals its line of the run's trajectory file (the file's
//     printed precision), no gap, at most the first second or so missed while connecting; the
//     last /plumb/trajectory holds every valid line (float precision);
//   - camera poses, /tf, the point cloud's byte layout, the JPEG image, status ends "ended".
// Usage: node ws_protocol_check.js PLUMB WORK_DIR
'use strict';
const fs = require('fs');
const path = require('path');
const WebSocket = require('ws');
const { FoxgloveClient } = require('@foxglove/ws-protocol');
const { startServing, readTum, check } = require('./plumb_process');

const EXPECTED = {
  '/plumb/camera_pose': ['foxglove.PoseInFrame', ['timestamp', 'frame_id', 'pose']],
  '/tf': ['foxglove.FrameTransform', ['timestamp', 'parent_frame_id', 'child_frame_id', 'translation', 'rotation']],
  '/plumb/output_pose': ['foxglove.PoseInFrame', ['timestamp', 'frame_id', 'pose']],
  '/plumb/trajectory': ['foxglove.SceneUpdate', ['deletions', 'entities']],
  '/plumb/loops': ['foxglove.SceneUpdate', ['deletions', 'entities']],
  '/plumb/map_points': ['foxglove.PointCloud', ['timestamp', 'frame_id', 'pose', 'point_stride', 'fields', 'data']],
  '/plumb/map_lines': ['foxglove.SceneUpdate', ['deletions', 'entities']],
  '/plumb/keyframes': ['foxglove.SceneUpdate', ['deletions', 'entities']],
  '/plumb/image': ['foxglove.CompressedImage', ['timestamp', 'frame_id', 'data', 'format']],
  '/plumb/status': ['plumb.Status', ['state', 'latency_ms', 'frames_dropped', 'loops', 'point_inliers']],
};

async function main() {
  const [plumb, work] = process.argv.slice(2);
  fs.rmSync(work, { recursive: true, force: true });
  fs.mkdirSync(work, { recursive: true });
  const traj = path.join(work, 'traj.txt');
  // Paced at 30 Hz (5 s), fast mode: the deterministic bytes on threads, as a robot would run.
  const run = await startServing(plumb, ['run', '--dataset', 'paced:synth:textured:1:150', '--mode', 'fast',
                                         '--out', traj, '--serve', '0']);
  const decoder = new TextDecoder();
  const byTopic = new Map();  // topic -> [messages]
  const channelsByTopic = new Map();
  const topicBySubscription = new Map();
  let serverInfo = null;
  const client = new FoxgloveClient({
    ws: new WebSocket(`ws://127.0.0.1:${run.port}/`, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]),
  });
  client.on('serverInfo', (info) => { serverInfo = info; });
  client.on('advertise', (channels) => {
    for (const c of channels) {
      channelsByTopic.set(c.topic, c);
      topicBySubscription.set(client.subscribe(c.id), c.topic);
    }
  });
  client.on('message', ({ subscriptionId, data }) => {
    const topic = topicBySubscription.get(subscriptionId);
    const text = decoder.decode(new Uint8Array(data.buffer, data.byteOffset, data.byteLength));
    if (!byTopic.has(topic)) byTopic.set(topic, []);
    byTopic.get(topic).push(JSON.parse(text));
  });
  const closed = new Promise((resolve) => client.on('close', resolve));
  const { code } = await run.exited;
  await Promise.race([closed, new Promise((r) => setTimeout(r, 5000))]);
  check(code === 0, `plumb run exited ${code}:\n${run.output()}`);

  check(serverInfo && serverInfo.name === 'plumb run', `serverInfo: ${JSON.stringify(serverInfo)}`);
  for (const [topic, [schemaName, fields]] of Object.entries(EXPECTED)) {
    const c = channelsByTopic.get(topic);
    check(c, `channel ${topic} not advertised`);
    check(c.schemaName === schemaName, `${topic}: schemaName ${c.schemaName}, expected ${schemaName}`);
    check(c.encoding === 'json' && c.schemaEncoding === 'jsonschema', `${topic}: ${c.encoding}/${c.schemaEncoding}`);
    const schema = JSON.parse(c.schema);
    check(schema.type === 'object' && schema.title === schemaName, `${topic}: schema title ${schema.title}`);
    for (const f of fields) check(f in schema.properties, `${topic}: schema lacks ${f}`);
    const messages = byTopic.get(topic) || [];
    if (topic !== '/plumb/loops') check(messages.length > 0, `no message on ${topic}`);
    for (const f of fields) check(messages.every((m) => f in m), `${topic}: a message lacks ${f}`);
  }

  // Output poses against the file.
  const file = readTum(traj);
  const received = byTopic.get('/plumb/output_pose');
  const stamp = (m) => m.timestamp.sec + m.timestamp.nsec * 1e-9;
  const first = file.findIndex((l) => Math.abs(l.t - stamp(received[0])) < 1e-6);
  check(first >= 0, `first output pose ${stamp(received[0])} is no line of the file`);
  check(first <= 45, `connected late: the first ${first} output poses were missed`);
  check(received.length === file.length - first,
        `received ${received.length} output poses from line ${first}, file has ${file.length} valid lines`);
  const near = (a, b) => Math.abs(a - b) <= 1e-8 * Math.max(1, Math.abs(b));  // the file prints %.9g
  received.forEach((m, i) => {
    const l = file[first + i];
    const p = m.pose.position, q = m.pose.orientation;
    check(Math.abs(stamp(m) - l.t) < 1e-6, `pose ${i}: time ${stamp(m)} vs ${l.t}`);
    const got = [p.x, p.y, p.z, q.x, q.y, q.z, q.w], want = [...l.p, ...l.q];
    got.forEach((v, k) => check(near(v, want[k]), `pose at ${l.t}: value ${k} ${v} vs file ${want[k]}`));
  });
  const trajectories = byTopic.get('/plumb/trajectory');
  const last = trajectories[trajectories.length - 1];
  const output = last.entities.find((e) => e.id === 'output');
  const points = output.lines.flatMap((l) => l.points);
  check(points.length === file.length, `final trajectory holds ${points.length} points, file ${file.length} lines`);
  points.forEach((pt, i) => {
    const d = Math.hypot(pt.x - file[i].p[0], pt.y - file[i].p[1], pt.z - file[i].p[2]);
    check(d < 1e-5, `trajectory point ${i} is ${d} m from the file's`);
  });

  // The live channels.
  const poses = byTopic.get('/plumb/camera_pose');
  check(poses.length >= 100, `only ${poses.length} camera poses`);
  check(byTopic.get('/tf').every((t) => t.parent_frame_id === 'world' && t.child_frame_id === 'camera'), '/tf frames');
  for (const cloud of byTopic.get('/plumb/map_points')) {
    const bytes = Buffer.from(cloud.data, 'base64');
    check(cloud.point_stride === 12 && bytes.length % 12 === 0, 'point cloud layout');
    check(cloud.fields.map((f) => `${f.name}:${f.offset}:${f.type}`).join(' ') === 'x:0:7 y:4:7 z:8:7', 'fields');
  }
  check(byTopic.get('/plumb/map_points').some((c) => c.data.length > 0), 'every point cloud is empty');
  for (const image of byTopic.get('/plumb/image')) {
    const jpeg = Buffer.from(image.data, 'base64');
    check(image.format === 'jpeg' && jpeg[0] === 0xff && jpeg[1] === 0xd8 && jpeg.length > 1000, 'image is no JPEG');
  }
  const statuses = byTopic.get('/plumb/status');
  check(statuses[statuses.length - 1].state === 'ended', `last status ${statuses[statuses.length - 1].state}`);
  check(statuses.some((s) => s.state === 'ok' && s.latency_ms > 0), 'no status with state ok and a latency');
  console.log(`viewer_foxglove_client: ${Object.keys(EXPECTED).length} channels checked; ${received.length} of ` +
              `${file.length} output poses equal the file (first ${first} missed while connecting); ` +
              `${poses.length} camera poses, ${byTopic.get('/plumb/image').length} images, ` +
              `${byTopic.get('/plumb/map_points').length} point clouds`);
}

main().then(() => process.exit(0), (e) => {
  console.error('FAIL viewer_foxglove_client:', e.message);
  process.exit(1);
});
