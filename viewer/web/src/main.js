// plumb's viewer page (docs/VIEWER.md): connects to the server that served it (the Foxglove
// WebSocket protocol on the same port) and draws what `plumb run --serve` or `plumb view` sends.
// window.plumbViewer exposes counters for tests (tests/viewer_node/page_test.js).
import { FoxgloveClient } from './foxglove_client.js';
import { Scene } from './scene.js';

const TOPICS = ['/plumb/camera_pose', '/plumb/trajectory', '/plumb/loops', '/plumb/map_points', '/plumb/map_lines',
                '/plumb/keyframes', '/plumb/image', '/plumb/status'];
const stats = { connected: false, messages: 0, posesReceived: 0, posesDrawn: 0, mapPoints: 0, status: null };
window.plumbViewer = stats;

const $ = (id) => document.getElementById(id);
const scene = new Scene($('scene'));

$('follow').addEventListener('change', (e) => { scene.follow = e.target.checked; });
$('show-map').addEventListener('change', (e) => {
  for (const c of ['/plumb/map_points', '/plumb/map_lines']) scene.setVisible(c, e.target.checked);
});
$('show-image').addEventListener('change', (e) => { $('image').style.display = e.target.checked && $('image').src ? 'block' : 'none'; });

const fixed = (v, digits) => (typeof v === 'number' && v >= 0 ? v.toFixed(digits) : '-');

function showStatus(s) {
  stats.status = s;
  $('title').textContent = s.mode ? `(${s.mode})` : '';
  $('state').textContent = s.state;
  $('state').className = 'v state-' + s.state;
  $('frame').textContent = `${s.frame} (${fixed(s.frame_timestamp, 3)} s)`;
  $('latency').textContent = s.latency_ms >= 0 ? `${fixed(s.latency_ms, 1)} ms (${fixed(s.latency_p99_ms, 1)})` : '-';
  $('inliers').textContent = `${s.point_inliers} / ${s.line_inliers}`;
  $('keyframes').textContent = s.keyframes;
  $('loops').textContent = s.loops;
  $('drops').textContent = `${s.frames_dropped} / ${s.frames_lost}`;
  $('map').textContent = `${s.map_points} / ${s.map_lines}`;
  if (typeof s.ate_rmse_m === 'number' && s.ate_rmse_m >= 0) {
    $('ate-row').style.display = '';
    $('ate').textContent = `${s.ate_rmse_m.toFixed(4)} m`;
  }
  if (typeof s.error_max_m === 'number' && s.error_max_m > 0) {
    $('errorbar').style.display = 'block';
    $('error-max').textContent = s.error_max_m.toFixed(3);
  }
}

function onMessage(topic, message) {
  stats.messages++;
  switch (topic) {
    case '/plumb/camera_pose':
      stats.posesReceived++;
      scene.cameraPose(message);
      break;
    case '/plumb/trajectory': {
      const counts = scene.sceneUpdate(topic, message);
      stats.posesDrawn = (counts.output || 0) + (counts.tracked || 0) + (counts.estimate || 0);
      if (finishedRun && !fitted) {
        scene.fitTo(topic);
        fitted = true;
      }
      break;
    }
    case '/plumb/map_points':
      stats.mapPoints = scene.pointCloud(topic, message);
      break;
    case '/plumb/image':
      $('image').src = 'data:image/jpeg;base64,' + message.data;
      $('image').style.display = $('show-image').checked ? 'block' : 'none';
      break;
    case '/plumb/status':
      showStatus(message);
      break;
    default:
      scene.sceneUpdate(topic, message);
  }
}

// `plumb view` serves a finished run: the whole trajectory in view, no follow-camera.
let finishedRun = false, fitted = false;
function onServerInfo(info) {
  finishedRun = info.name === 'plumb view';
  if (finishedRun) {
    scene.follow = false;
    $('follow').checked = false;
  }
}

const url = `${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/`;
new FoxgloveClient(url, TOPICS, {
  onMessage,
  onServerInfo,
  onOpen: () => {
    stats.connected = true;
    $('connection').textContent = `connected to ${location.host}`;
  },
  onClose: () => {
    stats.connected = false;
    $('connection').textContent = 'disconnected (retrying)';
  },
});
