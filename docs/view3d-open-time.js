// Time to the first frame of report.html's 3D view in headless Chromium, in real time
// through the DevTools protocol (node >= 20; Debian `chromium` with SwiftShader WebGL):
//
//   node --experimental-websocket docs/view3d-open-time.js 'file:///ABS/out/report.html#view3d'
//
// Prints wall_ms (navigation to the first frame, polled every 20 ms), first_frame_ms (the
// view's own performance.now() at its first frame), load_event_ms and any page errors.
const { spawn } = require('child_process');
const http = require('http');
const url = process.argv[2];
const port = 9339;
const chrome = spawn('chromium', ['--headless', '--no-sandbox', '--use-angle=swiftshader',
  '--enable-unsafe-swiftshader', '--no-first-run', '--window-size=1280,800',
  `--user-data-dir=${require('os').tmpdir()}/view3d-open-time-${process.pid}`, `--remote-debugging-port=${port}`, 'about:blank'],
  { stdio: 'ignore' });
const get = (p) => new Promise((res, rej) => http.get({ host: '127.0.0.1', port, path: p }, (r) => {
  let b = ''; r.on('data', (c) => b += c); r.on('end', () => res(JSON.parse(b)));
}).on('error', rej));
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
(async () => {
  let targets;
  for (let i = 0; i < 50; i++) { try { targets = await get('/json/list'); break; } catch { await sleep(200); } }
  const page = targets.find((t) => t.type === 'page');
  const ws = new WebSocket(page.webSocketDebuggerUrl);
  await new Promise((r) => ws.onopen = r);
  let id = 0; const pending = {};
  ws.onmessage = (m) => { const d = JSON.parse(m.data); if (d.id && pending[d.id]) { pending[d.id](d.result); delete pending[d.id]; } };
  const send = (method, params = {}) => new Promise((r) => { pending[++id] = r; ws.send(JSON.stringify({ id, method, params })); });
  await send('Page.enable');
  const t0 = Date.now();
  await send('Page.navigate', { url });
  let out;
  for (;;) {
    const r = await send('Runtime.evaluate', { expression:
      "(() => { const v = document.getElementById('view3d'); return v ? [v.dataset.drawn, v.dataset.firstFrameMs, v.dataset.errors, performance.timing.loadEventEnd - performance.timing.navigationStart] : null })()", returnByValue: true });
    out = r && r.result && r.result.value;
    if (out && out[0] === '1') break;
    if (Date.now() - t0 > 60000) break;
    await sleep(20);
  }
  console.log(JSON.stringify({ wall_ms: Date.now() - t0, drawn: out && out[0], first_frame_ms: out && Number(out[1]), errors: out && out[2], load_event_ms: out && out[3] }));
  ws.close(); chrome.kill();
  process.exit(0);
})();
