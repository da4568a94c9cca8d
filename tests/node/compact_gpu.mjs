// A real GPU runs the shipped compact decoder: headless Chromium (WebGL 2 on SwiftShader) loads
// a .brdfc (parsed here from docs/formats/compact.md: header, θin list, per-slice row and
// column lists, half-float log2 grid), builds the decoder's three textures (RGB16F grid,
// RGBA32F row maps, R32F column maps) and evaluates MeasuredBrdf(n, l, v) of the engine kit's
// MeasuredBrdf*.compact.es300.glsl for every direction pair of PAIRS into an RGBA32F target.
// PAIRS: little-endian float32 sextuples l.xyz, v.xyz (unit vectors, normal +z) per pair.
// Writes OUT as float32 RGB per pair, for tests/python/compact_check.py.
// Usage: node compact_gpu.mjs --brdfc FILE --glsl FILE --pairs FILE --out FILE [--chromium PATH]
import { createServer } from 'node:http';
import { readFileSync, writeFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { runPageFunction, startChromium } from './headless_chromium.mjs';

const args = {};
for (let i = 2; i < process.argv.length; i += 2) args[process.argv[i].slice(2)] = process.argv[i + 1];
for (const required of ['brdfc', 'glsl', 'pairs', 'out'])
  if (!args[required]) { console.error(`compact_gpu: --${required} is required`); process.exit(2); }
const files = {
  '/lut.brdfc': readFileSync(resolve(args.brdfc)),
  '/decoder.glsl': readFileSync(resolve(args.glsl)),
  '/pairs.f32': readFileSync(resolve(args.pairs)),
};
const webglPageScript = readFileSync(new URL('./webgl_page.js', import.meta.url));
const chromium = args.chromium || 'chromium';
const deadline = Date.now() + 240000;

const page = `<!doctype html><canvas id="c" width="4" height="4"></canvas>
<script src="/webgl_page.js"></script><script>
// The .brdfc container (docs/formats/compact.md), little-endian.
function parseCompact(buf) {
  const dv = new DataView(buf);
  const magic = String.fromCharCode(...new Uint8Array(buf, 0, 8));
  if (magic !== 'BRDFCLUT') throw new Error('not a compact LUT: ' + magic);
  if (dv.getUint32(8, true) !== 1) throw new Error('version ' + dv.getUint32(8, true));
  const K = dv.getUint32(12, true), mirrored = dv.getUint32(16, true) === 1;
  const scale = dv.getFloat32(20, true), epsilon = dv.getFloat32(24, true);
  let at = 36;
  const thetaIn = [];
  for (let k = 0; k < K; k++, at += 8) thetaIn.push(dv.getFloat64(at, true));
  const sizes = [];
  for (let k = 0; k < K; k++, at += 4) sizes.push([dv.getUint16(at, true), dv.getUint16(at + 2, true)]);
  const rows = [], cols = [];
  for (let k = 0; k < K; k++) {
    const r = [], c = [];
    for (let p = 0; p < sizes[k][0]; p++, at += 2) r.push(dv.getUint16(at, true));
    for (let p = 0; p < sizes[k][1]; p++, at += 2) c.push(dv.getUint16(at, true));
    rows.push(r); cols.push(c);
  }
  const values = [];
  for (let k = 0; k < K; k++) {
    const n = sizes[k][0] * sizes[k][1] * 3;
    values.push(new Uint16Array(buf.slice(at, at + 2 * n)));
    at += 2 * n;
  }
  return { K, mirrored, scale, epsilon, thetaIn, rows, cols, values };
}
// m(x) = p + (x - a_p)/(a_{p+1} - a_p) on the gap holding x, at whole degrees.
function mapTable(kept, n, fold) {
  const t = new Float32Array(n);
  for (let x = 0; x < n; x++) {
    const y = fold > 0 && x > fold ? 2 * fold - x : x;
    let p = 0;
    while (p + 2 < kept.length && kept[p + 1] <= y) p++;
    t[x] = p + (y - kept[p]) / (kept[p + 1] - kept[p]);
  }
  return t;
}
window.runAll = async () => {
  const lut = parseCompact(await (await fetch('/lut.brdfc')).arrayBuffer());
  const decoder = await (await fetch('/decoder.glsl')).text();
  const pairs = new Float32Array(await (await fetch('/pairs.f32')).arrayBuffer());
  const n = pairs.length / 6;
  const gl = document.getElementById('c').getContext('webgl2');
  if (!gl.getExtension('EXT_color_buffer_float')) throw new Error('no EXT_color_buffer_float');
  const K = lut.K;
  // Grid: slices stacked, width = the largest column count.
  let width = 0, height = 0;
  const row0 = [];
  for (let k = 0; k < K; k++) { width = Math.max(width, lut.cols[k].length); row0.push(height); height += lut.rows[k].length; }
  const grid = new Uint16Array(width * height * 3);
  for (let k = 0; k < K; k++) {
    const nc = lut.cols[k].length;
    for (let r = 0; r < lut.rows[k].length; r++)
      grid.set(lut.values[k].subarray(r * nc * 3, (r + 1) * nc * 3), ((row0[k] + r) * width) * 3);
  }
  const rowMaps = new Float32Array(181 * K * 4), colMaps = new Float32Array(361 * K);
  for (let k = 0; k < K; k++) {
    const rm = mapTable(lut.rows[k], 181, 0), cm = mapTable(lut.cols[k], 361, lut.mirrored ? 180 : 0);
    for (let x = 0; x < 181; x++)
      rowMaps.set([rm[x], row0[k], lut.rows[k].length - 1, lut.cols[k].length - 1], (k * 181 + x) * 4);
    colMaps.set(cm, k * 361);
  }
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  const texture = (unit, internal, format, type, w, h, data) => {
    const t = gl.createTexture();
    gl.activeTexture(gl.TEXTURE0 + unit);
    gl.bindTexture(gl.TEXTURE_2D, t);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
    gl.texImage2D(gl.TEXTURE_2D, 0, internal, w, h, 0, format, type, data);
    const e = gl.getError();
    if (e !== gl.NO_ERROR) throw new Error('texImage2D: GL error 0x' + e.toString(16));
  };
  texture(0, gl.RGB16F, gl.RGB, gl.HALF_FLOAT, width, height, grid);
  texture(1, gl.RGBA32F, gl.RGBA, gl.FLOAT, 181, K, rowMaps);
  texture(2, gl.R32F, gl.RED, gl.FLOAT, 361, K, colMaps);
  const W = 256, H = Math.ceil(n / W);
  const pairTex = new Float32Array(2 * W * H * 3);
  pairTex.set(pairs);
  texture(3, gl.RGB32F, gl.RGB, gl.FLOAT, 2 * W, H, pairTex);
  const fs = decoder + '\\nuniform highp sampler2D pairs; out vec4 color;\\n' +
    'void main() {\\n' +
    '  ivec2 p = ivec2(gl_FragCoord.xy);\\n' +
    '  vec3 l = texelFetch(pairs, ivec2(2 * p.x, p.y), 0).rgb;\\n' +
    '  vec3 v = texelFetch(pairs, ivec2(2 * p.x + 1, p.y), 0).rgb;\\n' +
    '  color = vec4(MeasuredBrdf(vec3(0.0, 0.0, 1.0), l, v), 1.0);\\n' +
    '}\\n';
  const prog = webglPage.program(gl, webglPage.fullScreenVertexShader, fs);
  const uni = (name) => gl.getUniformLocation(prog, name);
  gl.uniform1i(uni('measured_brdf_compact_grid'), 0);
  gl.uniform1i(uni('measured_brdf_compact_rows'), 1);
  gl.uniform1i(uni('measured_brdf_compact_cols'), 2);
  gl.uniform1i(uni('pairs'), 3);
  gl.uniform1f(uni('measured_brdf_compact_scale'), lut.scale);
  gl.uniform1f(uni('measured_brdf_compact_epsilon'), lut.epsilon);
  webglPage.fullScreenTriangle(gl, prog);
  gl.activeTexture(gl.TEXTURE4);  // units 0-3 hold the decoder's textures and the pairs
  webglPage.floatTarget(gl, W, H);
  gl.drawArrays(gl.TRIANGLES, 0, 3);
  const px = new Float32Array(W * H * 4);
  gl.readPixels(0, 0, W, H, gl.RGBA, gl.FLOAT, px);
  const e2 = gl.getError();
  if (e2 !== gl.NO_ERROR) throw new Error('GL error 0x' + e2.toString(16));
  const out = new Float32Array(n * 3);
  for (let i = 0; i < n; i++) for (let c = 0; c < 3; c++) out[i * 3 + c] = px[i * 4 + c];
  return { n, K, renderer: gl.getParameter(gl.RENDERER), data: webglPage.base64(out) };
};
</script>`;

const server = createServer((req, res) => {
  if (files[req.url]) { res.writeHead(200, { 'Content-Type': 'application/octet-stream' }); res.end(files[req.url]); }
  else if (req.url === '/webgl_page.js') { res.writeHead(200, { 'Content-Type': 'text/javascript' }); res.end(webglPageScript); }
  else if (req.url === '/') { res.writeHead(200, { 'Content-Type': 'text/html' }); res.end(page); }
  else { res.writeHead(404); res.end(); }
});
await new Promise((ok) => server.listen(0, '127.0.0.1', ok));
const { send, fail, cleanup } = await startChromium({ chromium, name: 'compact_gpu', deadline, server });
try {
  const result = await runPageFunction({ send, fail, url: `http://127.0.0.1:${server.address().port}/`,
                                         fnName: 'runAll', deadline });
  writeFileSync(resolve(args.out), Buffer.from(result.data, 'base64'));
  console.log(`compact_gpu: ${result.n} pairs over ${result.K} slices evaluated on ${result.renderer}`);
} catch (e) {
  fail(e.message);
}
cleanup();
process.exit(0);
