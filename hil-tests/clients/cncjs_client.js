// Drives the real CNCjs (npm) against taut as its web UI would: starts the
// CNCjs server headless on a free localhost port with a config of its own
// (a secret, no remote access, a watch directory), signs in through its
// REST API (/api/signin: no users, so it hands out a token), connects with
// socket.io (the client from CNCjs's own node_modules), opens PORT as a
// Grbl controller at 115200, loads FILE from the watch directory
// (`watchdir:load`), starts it (`gcode:start`), and once a third of it is
// acknowledged sends `feedhold`, waits in Hold for HOLD_S seconds, then
// `cyclestart`, and waits for CNCjs to end the job (workflow back to idle,
// the machine Idle). Last it presses CNCjs's Reset (Ctrl-X) and waits for
// CNCjs to read the banner that follows (its Grbl version).
//
// stdout, one event a line, for the test to parse, each as
// `cncjs: SECONDS EVENT`, SECONDS since the script started:
//   cncjs: server <url>            the server listens
//   cncjs: open <port>             the port is open
//   cncjs: state <activeState>     CNCjs's Grbl state changed (controller:state)
//   cncjs: workflow <state>        idle | running | paused (workflow:state)
//   cncjs: read <line>             what CNCjs shows in its console (serialport:read)
//   cncjs: sender <received>/<total>  how far the job is acknowledged, on change
//   cncjs: command <name>          a command sent (gcode:start, feedhold, cyclestart, reset)
//   cncjs: version <v>             the Grbl version CNCjs took from a banner
//   cncjs: done <why>              all went as planned (exit 0)
//   cncjs: fail <why>              it did not (exit 1; the server's log follows on stderr)
//
// With FILE `buttons:LINE|LINE|…` it streams no job: once ready it sends
// those lines as CNCjs's buttons do (`command('gcode', line)`: the jog
// arrows' `G91`, `G0 X10`, `G90`, "Zero Out Work Offsets"' `G10 L20 P1 X0
// Y0 Z0`, "Go To Work Zero"'s `G0 X0 Y0 Z0`), waits for each `ok` and for
// Idle, and ends (`cncjs: done buttons`).
//
// usage: node cncjs_client.js PORT CNCJS_PREFIX FILE TIMEOUT_S HOLD_S

'use strict';

const { spawn } = require('child_process');
const crypto = require('crypto');
const fs = require('fs');
const os = require('os');
const path = require('path');

const [port, prefix, file, timeoutS, holdS] = process.argv.slice(2);
const modules = path.resolve(prefix, 'node_modules');
const io = require(path.join(modules, 'socket.io-client'));

const started = Date.now();
const say = (what) => process.stdout.write(`cncjs: ${((Date.now() - started) / 1000).toFixed(3)} ${what}\n`);
const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'taut-cncjs-'));
const watch = path.join(tmp, 'watch');
fs.mkdirSync(watch);
const buttons = file.startsWith('buttons:') ? file.slice('buttons:'.length).split('|') : null;
const name = path.basename(file);
if (!buttons) fs.copyFileSync(file, path.join(watch, name));
const config = path.join(tmp, 'cncrc.json');
fs.writeFileSync(
  config,
  JSON.stringify({
    secret: crypto.randomBytes(24).toString('hex'),
    allowRemoteAccess: false,
    watchDirectory: watch,
    controller: 'Grbl',
  }),
);

let serverLog = '';
const server = spawn(
  process.execPath,
  [path.join(modules, 'cncjs/bin/cncjs'), '--host', '127.0.0.1', '--port', '0', '--config', config, '--controller', 'Grbl'],
  { stdio: ['ignore', 'pipe', 'pipe'] },
);
let socket = null;
let finished = false;

function finish(code, why) {
  if (finished) return;
  finished = true;
  say(`${code === 0 ? 'done' : 'fail'} ${why}`);
  if (code !== 0) process.stderr.write(serverLog);
  if (socket) socket.close();
  server.kill('SIGTERM');
  fs.rmSync(tmp, { recursive: true, force: true });
  // Let stdout drain, then go.
  setTimeout(() => process.exit(code), 100);
}

setTimeout(() => finish(1, `timed out after ${timeoutS} s`), Number(timeoutS) * 1000);
server.on('exit', (code, signal) => {
  finish(1, `the CNCjs server exited (${code ?? signal})`);
});

let url = null;
const onServerOutput = (chunk) => {
  serverLog += chunk;
  const m = !url && serverLog.match(/Starting the server at (http:\/\/127\.0\.0\.1:\d+)/);
  if (m) {
    url = m[1];
    say(`server ${url}`);
    connect().catch((e) => finish(1, `${e.stack || e}`));
  }
};
server.stdout.on('data', onServerOutput);
server.stderr.on('data', onServerOutput);

async function connect() {
  // As the web UI does first: sign in (no users configured: a token).
  const res = await fetch(`${url}/api/signin`, {
    method: 'POST',
    headers: { 'Content-Type': 'application/json' },
    body: JSON.stringify({ token: '' }),
  });
  const { token } = await res.json();
  if (!token) throw new Error(`no token from /api/signin (${res.status})`);
  socket = io.connect(url, { query: `token=${token}`, transports: ['websocket'] });
  socket.on('connect_error', (e) => finish(1, `socket.io: ${e}`));
  socket.on('error', (e) => finish(1, `socket.io: ${e}`));
  socket.on('startup', () => {
    socket.emit('open', port, { controllerType: 'Grbl', baudrate: 115200 }, (err) => {
      if (err) finish(1, `open ${port}: ${err}`);
    });
  });
  socket.on('serialport:open', (o) => say(`open ${o.port}`));
  socket.on('serialport:error', (o) => finish(1, `serial port error: ${JSON.stringify(o.err)}`));
  socket.on('serialport:read', (line) => {
    say(`read ${line}`);
    // The `ok` that ends CNCjs's own `$$` on connecting: a job started
    // before it (the listing takes ~0.4 s) has CNCjs credit that `ok` to
    // its first line and send a line past the receive buffer.
    if (line === 'ok' && lastRead.startsWith('$')) {
      settingsRead = true;
      onState(activeState, true);
    } else if (step === 'buttons' && (line === 'ok' || line.startsWith('error'))) {
      if (line.startsWith('error')) finish(1, `${line} to a button's line`);
      answered += 1;
      check();
    }
    lastRead = line;
    if (step === 'reset' && line.startsWith('Grbl ')) {
      banner = true;
      check();
    }
  });
  socket.on('controller:state', (type, state) => onState(state.status && state.status.activeState));
  socket.on('controller:settings', (type, settings) => onVersion(settings.version));
  socket.on('workflow:state', onWorkflow);
  socket.on('sender:status', onSender);
}

const command = (cmd, ...args) => {
  say(`command ${cmd}`);
  socket.emit('command', port, cmd, ...args);
};

// The plan, step by step, advanced by CNCjs's events.
let step = 'connecting';
let activeState = '';
let workflow = 'idle';
let received = 0;
let total = 0;

let lastRead = '';
let settingsRead = false;
// Buttons' lines answered.
let answered = 0;

function onState(s, again = false) {
  if (!s || (s === activeState && !again)) return;
  if (!again) {
    activeState = s;
    say(`state ${s}`);
  }
  if (s === 'Alarm') finish(1, 'the machine reports Alarm');
  if (step === 'connecting' && s === 'Idle' && settingsRead && buttons) {
    step = 'buttons';
    for (const line of buttons) command('gcode', line);
  } else if (step === 'connecting' && s === 'Idle' && settingsRead) {
    // Ready: CNCjs has seen the banner or a status report.
    step = 'loading';
    socket.emit('command', port, 'watchdir:load', name, (err, sender) => {
      if (err) return finish(1, `watchdir:load ${name}: ${err}`);
      say(`loaded ${name}: ${sender.total} lines`);
      step = 'running';
      command('gcode:start');
    });
  } else if (step === 'holding' && s === 'Hold') {
    step = 'held';
    setTimeout(() => {
      step = 'resumed';
      command('cyclestart');
    }, Number(holdS) * 1000);
  }
  check();
}

function onWorkflow(w) {
  if (w === workflow) return;
  say(`workflow ${w}`);
  if (w === 'paused') finish(1, 'CNCjs paused the job (an error?)');
  const ended = workflow === 'running' && w === 'idle';
  workflow = w;
  if (ended) {
    if (step !== 'resumed') finish(1, `the job ended at step ${step}`);
    else step = 'ended';
  }
  check();
}

function onSender(s) {
  if (s.received === received && s.total === total) return;
  received = s.received;
  total = s.total;
  say(`sender ${received}/${total}`);
  if (step === 'running' && activeState === 'Run' && total > 0 && received >= total / 3) {
    step = 'holding';
    command('feedhold');
  }
}

let version = '';
let banner = false;
let job = '';

function onVersion(v) {
  if (!v || v === version) return;
  version = v;
  say(`version ${v}`);
  check();
}

function check() {
  if (step === 'buttons' && answered === buttons.length && activeState === 'Idle') {
    finish(0, 'buttons');
  } else if (step === 'ended' && activeState === 'Idle') {
    job = `${total} lines in ${((Date.now() - started) / 1000).toFixed(1)} s`;
    step = 'reset';
    command('reset');
  } else if (step === 'reset' && banner && version) {
    finish(0, job);
  }
}
