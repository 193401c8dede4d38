// Starts `plumb ... --serve 0` (any free loopback port) and finds the port in what it prints.
// Shared by the viewer's real-client tests; every address here is loopback.
'use strict';
const { spawn } = require('child_process');

// Resolves { child, port, output(), exited } once the server announced its address.
function startServing(plumb, args, { timeoutMs = 60000 } = {}) {
  return new Promise((resolve, reject) => {
    const child = spawn(plumb, args, { stdio: ['ignore', 'pipe', 'pipe'] });
    let text = '';
    let announced = false;
    const exited = new Promise((done) => child.on('exit', (code, signal) => done({ code, signal })));
    const timer = setTimeout(() => {
      child.kill('SIGKILL');
      reject(new Error(`plumb did not announce its address within ${timeoutMs} ms:\n${text}`));
    }, timeoutMs);
    const onData = (chunk) => {
      text += chunk.toString();
      const m = /(?:viewer at|serving) http:\/\/127\.0\.0\.1:(\d+)\//.exec(text);
      if (m && !announced) {
        announced = true;
        clearTimeout(timer);
        resolve({ child, port: Number(m[1]), output: () => text, exited });
      }
    };
    child.stdout.on('data', onData);
    child.stderr.on('data', onData);
    exited.then(({ code, signal }) => {
      if (!announced) {
        clearTimeout(timer);
        reject(new Error(`plumb exited (${code ?? signal}) before serving:\n${text}`));
      }
    });
  });
}

// The valid lines of a TUM trajectory file: [{t, p: [x,y,z], q: [x,y,z,w]}].
function readTum(path) {
  const fs = require('fs');
  const poses = [];
  for (const line of fs.readFileSync(path, 'utf8').split('\n')) {
    if (line === '' || line.startsWith('#')) continue;
    const v = line.trim().split(/\s+/).map(Number);
    poses.push({ t: v[0], p: v.slice(1, 4), q: v.slice(4, 8) });
  }
  return poses;
}

function check(condition, message) {
  if (!condition) throw new Error(message);
}

module.exports = { startServing, readTum, check };
