// A stand-in for `pneumid app` that answers the HTTP JSON API of docs/app.md
// by running the command-line program (for work on the page without the C++
// server). Usage: node mock_server.mjs PNEUMID --root DIR --token T --web DIR [--port N]
import http from 'node:http';
import fs from 'node:fs';
import path from 'node:path';
import os from 'node:os';
import crypto from 'node:crypto';
import { execFile, spawn } from 'node:child_process';

const argv = process.argv.slice(2);
const PNEUMID = path.resolve(argv[0]);
const opt = (k, d) => { const i = argv.indexOf(k); return i >= 0 ? argv[i + 1] : d; };
const ROOT = path.resolve(opt('--root', '.'));
const TOKEN = opt('--token', 'T');
const WEB = path.resolve(opt('--web', 'dist'));
const PORT = Number(opt('--port', '0'));
const TMP = fs.mkdtempSync(path.join(os.tmpdir(), 'pneumid-mock-'));

const datasets = new Map();
let run = { state: 'idle', proc: null, samples: 0, summary: null, log: '', clients: new Set(), t0: 0 };

function cli(args) {
  return new Promise((resolve, reject) => {
    execFile(PNEUMID, args, { cwd: TMP, maxBuffer: 1 << 26 }, (err, stdout, stderr) => {
      if (err) reject(new Error((stderr || err.message).trim().split('\n').pop()));
      else resolve(stdout);
    });
  });
}

function parseCsv(text) {
  const lines = text.split(/\r?\n/).filter((l) => l && !l.startsWith('#'));
  const header = lines[0].split(',').map((s) => s.trim());
  const cols = header.map(() => []);
  for (const l of lines.slice(1)) l.split(',').forEach((v, i) => cols[i]?.push(Number(v)));
  return { header, cols };
}

function decimate(a, n) {
  if (a.length <= 2000) return a;
  const k = Math.ceil(a.length / 2000);
  return a.filter((_, i) => i % k === 0);
}

function dataset(file, name, body) {
  const { header, cols } = parseCsv(fs.readFileSync(file, 'utf8'));
  const pick = (k, i) => (body[k] && header.includes(body[k]) ? body[k] : header[i]);
  const t = pick('t', 0), u = pick('u', 1), y = pick('y', 2);
  const col = (c) => cols[header.indexOf(c)];
  const id = 'd' + (datasets.size + 1);
  const ds = {
    id, name, columns: header, t, u, y, samples: col(t).length, Ts: col(t)[1] - col(t)[0],
    signals: { t: decimate(col(t)), u: decimate(col(u)), y: decimate(col(y)) }, decimated: col(t).length > 2000,
  };
  datasets.set(id, { ...ds, file });
  return ds;
}

// Simulated response of a continuous transfer function (Euler, fine steps) to u(t)
function simulate(tf, op, t, u) {
  const den = tf.den, num = tf.num, n = den.length - 1;
  if (n < 1 || num.length > n) return t.map(() => op.y0 ?? 0);
  const a = den.map((x) => x / den[0]), b = num.map((x) => x / den[0]);
  const bb = Array(n - b.length).fill(0).concat(b); // length n
  let x = Array(n).fill(0);
  const out = [];
  const h = 1e-4;
  let tt = t[0];
  const uAt = (s) => { let k = t.findIndex((v) => v > s); k = k < 0 ? t.length - 1 : Math.max(0, k - 1); return u[k] - (op.u0 ?? 0); };
  for (let i = 0; i < t.length; i++) {
    while (tt < t[i]) {
      const v = uAt(tt - (tf.delay ?? 0));
      const dx = x.map((_, j) => (j < n - 1 ? x[j + 1] : -a.slice(1).reverse().reduce((s, aj, k) => s + aj * x[k], 0) + v));
      x = x.map((xi, j) => xi + h * dx[j]);
      tt += h;
    }
    out.push(bb.slice().reverse().reduce((s, bj, k) => s + bj * x[k], 0) + (op.y0 ?? 0));
  }
  return out;
}

function controllerArgs(b, modelFile) {
  const a = ['--controller', b.controller ?? 'dmc'];
  if (b.rule) a.push('--rule', b.rule);
  for (const k of ['P', 'M', 'lambda']) if (b[k] !== undefined) a.push('--' + k, String(b[k]));
  if (b.response_time !== undefined) a.push('--response-time', String(b.response_time));
  if (b.model) {
    const m = typeof b.model === 'string' ? b.model : (fs.writeFileSync(modelFile, JSON.stringify({ models: [b.model] })), modelFile + '#' + b.model.method);
    a.push('--model', m);
  }
  if (b.Ts !== undefined) a.push('--Ts', String(b.Ts));
  return a;
}

async function handle(req, res, url, body) {
  const json = (code, obj) => { res.writeHead(code, { 'Content-Type': 'application/json' }); res.end(JSON.stringify(obj)); };
  const p = url.pathname;
  const b = () => (body.length ? JSON.parse(body.toString()) : {});
  if (p === '/api/version') return json(200, { version: 'mock', root: ROOT });
  if (p === '/api/files') {
    const dir = url.searchParams.get('dir') ?? '';
    const full = path.resolve(ROOT, dir);
    if (!full.startsWith(ROOT)) return json(403, { error: 'outside the root' });
    const entries = fs.readdirSync(full, { withFileTypes: true })
      .filter((e) => e.isDirectory() || /\.(csv|mat)$/.test(e.name))
      .map((e) => ({ name: e.name, type: e.isDirectory() ? 'dir' : 'file', size: e.isDirectory() ? 0 : fs.statSync(path.join(full, e.name)).size }));
    return json(200, { dir, entries });
  }
  if (p === '/api/data/open') {
    const q = b();
    const full = path.resolve(ROOT, q.path ?? '');
    if (!full.startsWith(ROOT) || !fs.existsSync(full)) return json(404, { error: `path: no file ${q.path}` });
    return json(200, dataset(full, path.basename(full), q));
  }
  if (p === '/api/data/upload') {
    const name = url.searchParams.get('name') ?? 'upload.csv';
    const f = path.join(TMP, 'upload-' + Date.now() + '-' + name);
    fs.writeFileSync(f, body);
    return json(200, dataset(f, name, Object.fromEntries(url.searchParams)));
  }
  if (p === '/api/identify') {
    const q = b();
    const ds = datasets.get(q.data);
    if (!ds) return json(404, { error: `data: no data set ${q.data}` });
    const out = path.join(TMP, 'models.json');
    const args = ['identify', ds.file, '-m', q.methods.join(','), '-o', out, '--json'];
    if (q.detrend) args.push('--detrend', q.detrend);
    if (q.window) args.push('--window', q.window);
    const r = JSON.parse(await cli(args));
    const mf = JSON.parse(fs.readFileSync(out, 'utf8'));
    const responses = { t: ds.signals.t };
    for (const m of mf.models) if (m.tf) responses[m.method] = simulate(m.tf, m.operating_point ?? {}, ds.signals.t, ds.signals.u);
    return json(200, { ...r, responses, model_file: mf });
  }
  if (p === '/api/control') {
    const q = b();
    const trace = path.join(TMP, 'trace.csv');
    const args = ['control', ...controllerArgs(q, path.join(TMP, 'model.json')), '--json', '-o', trace];
    if (q.plant) args.push('--plant', q.plant);
    if (q.setpoint) args.push('--setpoint', q.setpoint);
    if (q.duration !== undefined) args.push('--duration', String(q.duration));
    const r = JSON.parse(await cli(args));
    const { header, cols } = parseCsv(fs.readFileSync(trace, 'utf8'));
    const c = (re) => cols[header.findIndex((h) => re.test(h))] ?? [];
    return json(200, { ...r, trace: { t: c(/^t/), r: c(/^r/), y: c(/^y/), u: c(/^u/) } });
  }
  if (p === '/api/tune') {
    const q = b();
    const a = controllerArgs(q, path.join(TMP, 'tmodel.json'));
    const ctl = a.splice(0, 2)[1];
    if (q.rule === 'auto') a.push('--controller', ctl);
    return json(200, JSON.parse(await cli(['tune', ...a, '--json'])));
  }
  if (p === '/api/run/start') {
    if (run.state === 'running') return json(409, { error: 'a run is going on' });
    const q = b();
    const log = path.join(TMP, 'run.csv');
    fs.rmSync(log, { force: true });
    const args = ['run', ...controllerArgs(q, path.join(TMP, 'rmodel.json')), '--io', q.io ?? 'sim', '--log', log, '--json'];
    if (q.setpoint) args.push('--setpoint', q.setpoint);
    if (q.duration !== undefined) args.push('--duration', String(q.duration));
    const proc = spawn(PNEUMID, args, { cwd: TMP });
    let out = '';
    proc.stdout.on('data', (d) => (out += d));
    let err = '';
    proc.stderr.on('data', (d) => (err += d));
    run = { state: 'running', proc, samples: 0, summary: null, log, clients: run.clients, t0: Date.now(), sent: 0 };
    const tick = setInterval(() => {
      if (!fs.existsSync(log)) return;
      const { header, cols } = parseCsv(fs.readFileSync(log, 'utf8'));
      const n = cols[0].length;
      if (n > run.sent) {
        const c = (re) => cols[header.findIndex((h) => re.test(h))]?.slice(run.sent, n) ?? [];
        broadcast({ t: c(/^t/), r: c(/^r/), y: c(/^y/), u: c(/^u/) });
        run.sent = n;
        run.samples = n;
      }
    }, 50);
    proc.on('close', (code) => {
      clearInterval(tick);
      try { run.summary = JSON.parse(out); } catch { run.summary = { error: err.trim() }; }
      if (run.state === 'running') run.state = code === 0 ? 'finished' : 'failed';
      broadcast({ done: true, summary: run.summary });
    });
    return json(200, { state: 'running' });
  }
  if (p === '/api/run/status') return json(200, { state: run.state, samples: run.samples, elapsed: (Date.now() - run.t0) / 1000, summary: run.summary ?? undefined });
  if (p === '/api/run/stop') {
    if (run.state === 'running') { run.state = 'stopped'; run.proc.kill('SIGINT'); }
    return json(200, { state: run.state });
  }
  if (p === '/api/run/log') {
    if (!run.log || !fs.existsSync(run.log)) return json(404, { error: 'no run yet' });
    res.writeHead(200, { 'Content-Type': 'text/csv' });
    return res.end(fs.readFileSync(run.log));
  }
  if (p === '/api/export/controller') {
    const q = b();
    res.writeHead(200, { 'Content-Type': 'text/plain' });
    return res.end(`[loop]\nperiod = ${q.Ts ?? 0.01}\nduration = ${q.duration ?? 10}\n\n[io]\nbackend = "${q.io ?? 'sim'}"\n`);
  }
  if (p === '/api/export/report') {
    const q = b();
    const ds = datasets.get(q.data);
    if (!ds) return json(404, { error: `data: no data set ${q.data}` });
    const out = path.join(TMP, 'report');
    await cli(['report', ds.file, '-m', q.methods.join(','), '-o', out]);
    const html = fs.readdirSync(out).find((f) => f.endsWith('.html'));
    res.writeHead(200, { 'Content-Type': 'text/html' });
    return res.end(fs.readFileSync(path.join(out, html)));
  }
  return json(404, { error: 'no such path ' + p });
}

function broadcast(obj) {
  const data = Buffer.from(JSON.stringify(obj));
  let head;
  if (data.length < 126) head = Buffer.from([0x81, data.length]);
  else if (data.length < 65536) { head = Buffer.alloc(4); head[0] = 0x81; head[1] = 126; head.writeUInt16BE(data.length, 2); }
  else { head = Buffer.alloc(10); head[0] = 0x81; head[1] = 127; head.writeBigUInt64BE(BigInt(data.length), 2); }
  for (const s of run.clients) s.write(Buffer.concat([head, data]));
}

const server = http.createServer((req, res) => {
  const url = new URL(req.url, 'http://x');
  const chunks = [];
  req.on('data', (c) => chunks.push(c));
  req.on('end', async () => {
    if (url.pathname === '/' || url.pathname.startsWith('/assets/')) {
      const f = path.join(WEB, url.pathname === '/' ? 'index.html' : url.pathname);
      if (!fs.existsSync(f)) { res.writeHead(404); return res.end(); }
      const type = f.endsWith('.js') ? 'text/javascript' : f.endsWith('.css') ? 'text/css' : 'text/html';
      res.writeHead(200, { 'Content-Type': type });
      return res.end(fs.readFileSync(f));
    }
    const tok = url.searchParams.get('token') ?? req.headers['x-pneumid-token'];
    if (tok !== TOKEN) { res.writeHead(403, { 'Content-Type': 'application/json' }); return res.end('{"error":"token"}'); }
    try {
      await handle(req, res, url, Buffer.concat(chunks));
    } catch (e) {
      res.writeHead(400, { 'Content-Type': 'application/json' });
      res.end(JSON.stringify({ error: e.message }));
    }
  });
});
server.on('upgrade', (req, socket) => {
  const url = new URL(req.url, 'http://x');
  if (url.searchParams.get('token') !== TOKEN) return socket.destroy();
  const accept = crypto.createHash('sha1').update(req.headers['sec-websocket-key'] + '258EAFA5-E914-47DA-95CA-C5AB0DC85B11').digest('base64');
  socket.write(`HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Accept: ${accept}\r\n\r\n`);
  run.clients.add(socket);
  socket.on('close', () => run.clients.delete(socket));
  socket.on('error', () => run.clients.delete(socket));
  socket.on('data', (d) => { if ((d[0] & 0x0f) === 8) socket.end(); });
});
server.listen(PORT, '127.0.0.1', () => {
  console.log(`pneumid app (mock): http://127.0.0.1:${server.address().port}/?token=${TOKEN}`);
});
