// Headless Chromium (WebGL 2 on SwiftShader) driven through the DevTools protocol, shared by
// the browser tests (render_web.mjs, bc6h_gpu.mjs, compact_gpu.mjs). startChromium() launches the browser with
// a private profile folder, waits for its DevTools port and returns
//   send(method, params, sessionId)  one DevTools call, resolved with its result
//   fail(message)                    prints `name: message` and the browser's last log lines,
//                                    cleans up and exits 1
//   cleanup()                        closes the DevTools connection, kills the browser, closes
//                                    `server`, removes the profile
//   consoleLines                     the pages' console output and uncaught exceptions
// Every step is bounded by `deadline` (a Date.now() value): past it the script fails.
// serveFolders() is the static HTTP server the pages are loaded from; parseOptions() reads the
// scripts' `--name value` and `--flag` arguments.
import { spawn } from 'node:child_process';
import { createServer } from 'node:http';
import { mkdtempSync, readFileSync, existsSync, rmSync, statSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, extname, resolve } from 'node:path';
import WebSocket from 'ws';

// `--name value` pairs and bare `--flag`s (true) into an object; anything else throws.
export function parseOptions(argv) {
  const args = {};
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    if (!a.startsWith('--')) throw new Error(`unexpected argument ${a}`);
    const next = argv[i + 1];
    if (next === undefined || next.startsWith('--')) args[a.slice(2)] = true;
    else { args[a.slice(2)] = next; i++; }
  }
  return args;
}

const contentTypes = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript',
                       '.json': 'application/json' };

// Serves `routes` (URL prefix such as '/web/' -> folder; nothing outside a folder) and `pages`
// (exact path -> HTML text) on 127.0.0.1; resolves to { server, base } (base: 'http://...').
export async function serveFolders(routes, pages = {}) {
  const server = createServer((req, res) => {
    const path = new URL(req.url, 'http://127.0.0.1').pathname;
    if (pages[path] !== undefined) {
      res.writeHead(200, { 'Content-Type': 'text/html' });
      res.end(pages[path]);
      return;
    }
    const prefix = Object.keys(routes).find((p) => path.startsWith(p));
    const root = prefix && resolve(routes[prefix]);
    const file = root && resolve(root, decodeURIComponent(path.slice(prefix.length)));
    if (!file || !file.startsWith(root) || !existsSync(file) || !statSync(file).isFile()) {
      res.writeHead(404); res.end('not found'); return;
    }
    res.writeHead(200, { 'Content-Type': contentTypes[extname(file)] || 'application/octet-stream' });
    res.end(readFileSync(file));
  });
  await new Promise((ok) => server.listen(0, '127.0.0.1', ok));
  return { server, base: `http://127.0.0.1:${server.address().port}` };
}

export async function startChromium({ chromium, name, deadline, server, extraArgs = [] }) {
  const profile = mkdtempSync(join(tmpdir(), `brdf-${name}-`));
  const browser = spawn(chromium, [
    '--headless', '--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
    '--disable-gpu-sandbox', '--disable-background-networking', '--disable-component-update',
    '--disable-sync', '--no-first-run', '--no-default-browser-check', '--mute-audio',
    `--user-data-dir=${profile}`, '--remote-debugging-port=0', ...extraArgs, 'about:blank'],
    { stdio: ['ignore', 'ignore', 'pipe'] });
  let browserLog = '';
  let ws = null;
  browser.stderr.on('data', (d) => { browserLog += d; });
  const cleanup = () => {
    if (ws) ws.close();
    try { browser.kill('SIGKILL'); } catch { /* already gone */ }
    if (server) server.close();
    try { rmSync(profile, { recursive: true, force: true }); } catch { /* best effort */ }
  };
  const fail = (message) => {
    console.error(`${name}: ${message}`);
    if (browserLog) console.error(browserLog.split('\n').slice(-15).join('\n'));
    cleanup();
    process.exit(1);
  };
  const seconds = Math.round((deadline - Date.now()) / 1000);
  setTimeout(() => fail(`timed out after ${seconds} s`), deadline - Date.now()).unref();

  const sleep = (ms) => new Promise((ok) => setTimeout(ok, ms));
  let endpoint = null;
  while (!endpoint) {
    if (Date.now() > deadline) fail('chromium did not open its DevTools port');
    if (browser.exitCode !== null) fail(`chromium exited with code ${browser.exitCode}`);
    const portFile = join(profile, 'DevToolsActivePort');
    if (existsSync(portFile)) {
      const [port, path] = readFileSync(portFile, 'utf8').split('\n');
      if (port && path) endpoint = `ws://127.0.0.1:${port}${path}`;
    }
    if (!endpoint) await sleep(100);
  }

  ws = new WebSocket(endpoint, { perMessageDeflate: false, maxPayload: 1 << 30 });
  await new Promise((ok, bad) => { ws.once('open', ok); ws.once('error', bad); });
  let nextId = 1;
  const pending = new Map();
  const consoleLines = [];
  ws.on('message', (data) => {
    const msg = JSON.parse(data.toString());
    if (msg.id && pending.has(msg.id)) {
      const { ok, bad } = pending.get(msg.id);
      pending.delete(msg.id);
      if (msg.error) bad(new Error(JSON.stringify(msg.error))); else ok(msg.result);
    } else if (msg.method === 'Runtime.consoleAPICalled') {
      consoleLines.push(msg.params.args.map((a) => a.value ?? a.description).join(' '));
    } else if (msg.method === 'Runtime.exceptionThrown') {
      consoleLines.push('exception: ' + msg.params.exceptionDetails.exception?.description);
    }
  });
  const send = (method, params = {}, sessionId) => new Promise((ok, bad) => {
    const id = nextId++;
    pending.set(id, { ok, bad });
    ws.send(JSON.stringify({ id, method, params, ...(sessionId ? { sessionId } : {}) }));
  });
  return { send, fail, cleanup, consoleLines };
}

// Opens `url` in a new tab of the browser `send` drives and returns what the page's async
// function window[fnName]() resolves to (by value), polling every 100 ms until the page has
// defined it. An exception in the page, or `deadline` passing, fails through `fail`.
export async function runPageFunction({ send, fail, url, fnName, deadline }) {
  const { targetId } = await send('Target.createTarget', { url: 'about:blank' });
  const { sessionId } = await send('Target.attachToTarget', { targetId, flatten: true });
  await send('Page.enable', {}, sessionId);
  await send('Page.navigate', { url }, sessionId);
  for (;;) {
    if (Date.now() > deadline) fail('the page never loaded');
    const r = await send('Runtime.evaluate', {
      expression: `typeof window.${fnName} === "function" ? window.${fnName}() : null`,
      awaitPromise: true, returnByValue: true }, sessionId);
    if (r.exceptionDetails) fail(r.exceptionDetails.exception?.description || r.exceptionDetails.text);
    if (r.result.value) return r.result.value;
    await new Promise((ok) => setTimeout(ok, 100));
  }
}
