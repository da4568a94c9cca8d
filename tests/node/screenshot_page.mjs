// Opens a page of an already running web server in headless Chromium (WebGL 2 on SwiftShader),
// as a person opens it, waits until document.title is "ready" and writes a PNG screenshot of the
// window. A title "error", or none of the two before the deadline, fails with the page's log.
// Used by tests/tools/demo_web_test.py on the demo's environment-lit viewer.
// Usage: node screenshot_page.mjs --url URL --out FILE.png [--width 512] [--height 512]
//        [--chromium PATH] [--timeout-s 120]
import { writeFileSync } from 'node:fs';
import { parseOptions, startChromium } from './headless_chromium.mjs';

const args = parseOptions(process.argv.slice(2));
for (const required of ['url', 'out'])
  if (!args[required]) { console.error(`screenshot_page: --${required} is required`); process.exit(2); }
const width = parseInt(args.width || '512', 10), height = parseInt(args.height || '512', 10);
const deadline = Date.now() + 1000 * parseFloat(args['timeout-s'] || '120');
const { send, fail, cleanup, consoleLines } =
  await startChromium({ chromium: args.chromium || 'chromium', name: 'screenshot_page', deadline });
const { targetId } = await send('Target.createTarget', { url: 'about:blank' });
const { sessionId } = await send('Target.attachToTarget', { targetId, flatten: true });
await send('Emulation.setDeviceMetricsOverride', { width, height, deviceScaleFactor: 1, mobile: false }, sessionId);
await send('Runtime.enable', {}, sessionId);
await send('Page.navigate', { url: args.url }, sessionId);
let title = '';
for (;;) {
  if (Date.now() > deadline) fail(`${args.url}: document.title stayed "${title}"\n${consoleLines.join('\n')}`);
  title = (await send('Runtime.evaluate', { expression: 'document.title', returnByValue: true }, sessionId)).result.value;
  if (title === 'ready' || title === 'error') break;
  await new Promise((ok) => setTimeout(ok, 100));
}
if (title !== 'ready') {
  const status = (await send('Runtime.evaluate', {
    expression: "document.getElementById('status')?.textContent ?? ''", returnByValue: true }, sessionId)).result.value;
  fail(`${args.url}: document.title "${title}" (status: ${status})\n${consoleLines.join('\n')}`);
}
const shot = await send('Page.captureScreenshot', { format: 'png' }, sessionId);
writeFileSync(args.out, Buffer.from(shot.data, 'base64'));
console.log(JSON.stringify({ url: args.url, title, width, height }));
cleanup();
