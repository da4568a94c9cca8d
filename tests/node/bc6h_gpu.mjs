// A real GPU decodes our BC6H: headless Chromium (WebGL 2 on SwiftShader) uploads a KTX2 of
// vkFormat 131 as a compressed 3D texture (EXT_texture_compression_bptc,
// COMPRESSED_RGB_BPTC_UNSIGNED_FLOAT_EXT) and reads every texel of every slice back with
// texelFetch into an RGBA32F render target. No three.js: the KTX2 is parsed here (header and
// level index, KTX 2.0 §3) and handed to compressedTexImage3D as it is stored, at the size
// padded to whole blocks (WebGL requires BPTC level 0 sizes to be multiples of 4).
// Writes OUT as little-endian float32, depth × height × width × 3 (x fastest), for
// tests/python/bc6h_gpu_check.py.
// Usage: node bc6h_gpu.mjs --ktx2 FILE --out FILE [--chromium PATH]
import { createServer } from 'node:http';
import { readFileSync, writeFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { runPageFunction, startChromium } from './headless_chromium.mjs';

const args = {};
for (let i = 2; i < process.argv.length; i += 2) args[process.argv[i].slice(2)] = process.argv[i + 1];
for (const required of ['ktx2', 'out'])
  if (!args[required]) { console.error(`bc6h_gpu: --${required} is required`); process.exit(2); }
const ktx2 = readFileSync(resolve(args.ktx2));
const webglPageScript = readFileSync(new URL('./webgl_page.js', import.meta.url));
const chromium = args.chromium || 'chromium';
const deadline = Date.now() + 240000;

const page = `<!doctype html><canvas id="c" width="4" height="4"></canvas>
<script src="/webgl_page.js"></script><script>
window.readAll = async () => {
  const bytes = new Uint8Array(await (await fetch('/texture.ktx2')).arrayBuffer());
  const dv = new DataView(bytes.buffer);
  const vkFormat = dv.getUint32(12, true), w = dv.getUint32(20, true), h = dv.getUint32(24, true),
        d = dv.getUint32(28, true);
  if (vkFormat !== 131) throw new Error('vkFormat ' + vkFormat + ', expected 131');
  const offset = Number(dv.getBigUint64(80, true)), length = Number(dv.getBigUint64(88, true));
  const gl = document.getElementById('c').getContext('webgl2');
  const bptc = gl.getExtension('EXT_texture_compression_bptc');
  if (!bptc) throw new Error('no EXT_texture_compression_bptc');
  if (!gl.getExtension('EXT_color_buffer_float')) throw new Error('no EXT_color_buffer_float');
  const tex = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_3D, tex);
  gl.texParameteri(gl.TEXTURE_3D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
  gl.texParameteri(gl.TEXTURE_3D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
  // WebGL refuses BPTC level-0 sizes that are not multiples of 4; the file's blocks are exactly
  // those of the padded size (ceil(w/4)·ceil(h/4) blocks per slice either way), so the texture
  // is created at that size and only the w × h texels of the image are fetched.
  const pw = Math.ceil(w / 4) * 4, ph = Math.ceil(h / 4) * 4;
  gl.compressedTexImage3D(gl.TEXTURE_3D, 0, bptc.COMPRESSED_RGB_BPTC_UNSIGNED_FLOAT_EXT, pw, ph, d, 0,
                          bytes.subarray(offset, offset + length));
  const err = gl.getError();
  if (err !== gl.NO_ERROR) throw new Error('compressedTexImage3D: GL error 0x' + err.toString(16));
  const fs = '#version 300 es\\nprecision highp float; precision highp sampler3D;\\n' +
    'uniform sampler3D lut; uniform int slice; out vec4 color;\\n' +
    'void main() { color = vec4(texelFetch(lut, ivec3(int(gl_FragCoord.x), int(gl_FragCoord.y), slice), 0).rgb, 1.0); }';
  const prog = webglPage.program(gl, webglPage.fullScreenVertexShader, fs);
  webglPage.fullScreenTriangle(gl, prog);
  webglPage.floatTarget(gl, w, h);
  gl.activeTexture(gl.TEXTURE0);
  gl.bindTexture(gl.TEXTURE_3D, tex);
  gl.uniform1i(gl.getUniformLocation(prog, 'lut'), 0);
  const out = new Float32Array(w * h * d * 3), row = new Float32Array(w * h * 4);
  for (let z = 0; z < d; z++) {
    gl.uniform1i(gl.getUniformLocation(prog, 'slice'), z);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT, row);
    // gl_FragCoord.y = texel row y (texelFetch's t): row y of the texture is row y of the read.
    for (let i = 0; i < w * h; i++)
      for (let c = 0; c < 3; c++) out[(z * w * h + i) * 3 + c] = row[i * 4 + c];
  }
  const e2 = gl.getError();
  if (e2 !== gl.NO_ERROR) throw new Error('GL error 0x' + e2.toString(16));
  return { w, h, d, renderer: gl.getParameter(gl.RENDERER), data: webglPage.base64(out) };
};
</script>`;

const server = createServer((req, res) => {
  if (req.url === '/texture.ktx2') { res.writeHead(200, { 'Content-Type': 'application/octet-stream' }); res.end(ktx2); }
  else if (req.url === '/webgl_page.js') { res.writeHead(200, { 'Content-Type': 'text/javascript' }); res.end(webglPageScript); }
  else if (req.url === '/') { res.writeHead(200, { 'Content-Type': 'text/html' }); res.end(page); }
  else { res.writeHead(404); res.end(); }
});
await new Promise((ok) => server.listen(0, '127.0.0.1', ok));
const { send, fail, cleanup } = await startChromium({ chromium, name: 'bc6h_gpu', deadline, server });
try {
  const result = await runPageFunction({ send, fail, url: `http://127.0.0.1:${server.address().port}/`,
                                         fnName: 'readAll', deadline });
  writeFileSync(resolve(args.out), Buffer.from(result.data, 'base64'));
  console.log(`bc6h_gpu: ${result.w} x ${result.h} x ${result.d} texels fetched on ${result.renderer}`);
} catch (e) {
  fail(e.message);
}
cleanup();
process.exit(0);
