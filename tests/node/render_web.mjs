// Drives the exported web hand-off (OUT/web/) in real headless Chromium (WebGL 2 on
// SwiftShader) through the DevTools protocol and writes what the GPU computed, for the
// independent checks in tests/python/web_render_check.py:
//   image.f32       the shipped viewer's sphere rendered into a float render target (RGBA32F,
//                   rows top first), linear radiance, with image.json describing the camera
//   probes.json     the manifest's probe texels read back with texelFetch and with a filtered
//                   fetch at the texel centre
//   pairs_glsl.txt  MeasuredBrdfCell (the shipped GLSL) for each line "nx ny nz lx ly lz vx vy vz"
//                   of --pairs, one "r g b" line each; pairs_tangent.txt MeasuredBrdfTangent;
//                   pairs_sidecar.txt the sidecar's texel_convention.glsl (--sidecar FILE.json)
//   pairs_NAME.txt  the same through each GLSL ES harness of --es-harness NAME=FILE,...
//                   (the Unity and Unreal HLSL and the GLSL 4.50 file cross-compiled by
//                   glslangValidator and spirv-cross, the Godot shader translated)
//   exact_*.txt     the same for the exact directions of --exact
//   screenshot.png  the viewer as a person sees it (sRGB canvas), light moved once
//   bench.json      with --bench: frame times of a 1024² canvas, the measured material and
//                   three's MeshStandardMaterial (the baseline) alternating
// Usage: node render_web.mjs --web DIR --material NAME --out DIR [--size N] [--pairs FILE]
//        [--exact FILE] [--sidecar FILE.json] [--es-harness NAME=FILE,...]
//        [--cell NAME (an atlas material)] [--bench] [--chromium PATH]
import { readFileSync, writeFileSync, existsSync } from 'node:fs';
import { join, resolve, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { parseOptions, serveFolders, startChromium } from './headless_chromium.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const args = parseOptions(process.argv.slice(2));
for (const required of ['web', 'material', 'out'])
  if (!args[required]) { console.error(`render_web: --${required} is required`); process.exit(2); }
const webDir = resolve(args.web), outDir = resolve(args.out);
const threeDir = resolve(here, 'node_modules/three');
if (!existsSync(join(threeDir, 'build/three.module.js'))) {
  console.error('render_web: three is not installed in tests/node; run tools/install-npm-deps.sh');
  process.exit(1);
}
const size = parseInt(args.size || '256', 10);
const chromium = args.chromium || 'chromium';
const deadline = Date.now() + 240000;

// A static server for /web/ (the exported folder) and /three/ (the npm package).
const { server, base } = await serveFolders({ '/web/': webDir, '/three/': threeDir });

const { send, fail, cleanup, consoleLines } = await startChromium({
  chromium, name: 'render_web', deadline, server, extraArgs: ['--window-size=1100,1100'] });
const sleep = (ms) => new Promise((ok) => setTimeout(ok, ms));

async function openPage(url) {
  const { targetId } = await send('Target.createTarget', { url: 'about:blank' });
  const { sessionId } = await send('Target.attachToTarget', { targetId, flatten: true });
  await send('Runtime.enable', {}, sessionId);
  await send('Page.enable', {}, sessionId);
  await send('Page.navigate', { url }, sessionId);
  const page = {
    sessionId,
    async eval(expression) {
      const r = await send('Runtime.evaluate',
        { expression, awaitPromise: true, returnByValue: true }, sessionId);
      if (r.exceptionDetails)
        throw new Error(`${r.exceptionDetails.exception?.description || r.exceptionDetails.text}\n` +
                        consoleLines.join('\n'));
      return r.result.value;
    },
  };
  for (;;) {
    if (Date.now() > deadline) fail(`page ${url} never became ready\n${consoleLines.join('\n')}`);
    const state = await page.eval('window.measuredBrdf && window.measuredBrdf.ready ? "ok" : "wait"');
    if (state === 'ok') break;
    await sleep(100);
  }
  await page.eval('window.measuredBrdf.ready');
  return page;
}

// Code run inside the page: helpers on window.measuredBrdf.
const helpers = `
(() => {
  const M = window.measuredBrdf, THREE = M.THREE;
  const toBase64 = (floats) => {
    const bytes = new Uint8Array(floats.buffer);
    let s = '';
    for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode.apply(null, bytes.subarray(i, i + 0x8000));
    return btoa(s);
  };
  const floatTarget = (w, h) => new THREE.WebGLRenderTarget(w, h, { type: THREE.FloatType,
      format: THREE.RGBAFormat, minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter });
  const readTarget = (rt, w, h) => { const b = new Float32Array(w * h * 4); M.renderer.readRenderTargetPixels(rt, 0, 0, w, h, b); return b; };
  // Renders a fragment shader over a w × h target and returns its RGBA floats (rows bottom first).
  M.runFragment = (fragmentShader, uniforms, w, h) => {
    const material = new THREE.ShaderMaterial({ glslVersion: THREE.GLSL3, uniforms, fragmentShader,
      vertexShader: 'void main() { gl_Position = vec4(position.xy, 0.0, 1.0); }' });
    const scene = new THREE.Scene();
    scene.add(new THREE.Mesh(new THREE.PlaneGeometry(2, 2), material));
    const rt = floatTarget(w, h);
    M.renderer.setRenderTarget(rt);
    M.renderer.render(scene, new THREE.Camera());
    M.renderer.setRenderTarget(null);
    const out = readTarget(rt, w, h);
    rt.dispose(); material.dispose();
    return out;
  };
  M.dataTexture = (floats, w, h) => {
    const t = new THREE.DataTexture(floats, w, h, THREE.RGBAFormat, THREE.FloatType);
    t.minFilter = THREE.NearestFilter; t.magFilter = THREE.NearestFilter; t.needsUpdate = true;
    return t;
  };
  M.renderSphere = (size, light) => {
    M.renderer.setSize(size, size);
    M.camera.aspect = 1; M.camera.updateProjectionMatrix();
    M.shader.uniforms.encodeSrgb.value = false;
    M.shader.uniforms.lightDirection.value.set(light[0], light[1], light[2]).normalize();
    const rt = floatTarget(size, size);
    M.renderer.setRenderTarget(rt);
    M.renderer.render(M.scene, M.camera);
    M.renderer.setRenderTarget(null);
    M.shader.uniforms.encodeSrgb.value = true;
    const out = readTarget(rt, size, size);
    rt.dispose();
    return toBase64(out);
  };
  M.toBase64 = toBase64;
  return true;
})()`;

const fromBase64 = (s) => { const b = Buffer.from(s, 'base64'); return new Float32Array(b.buffer, b.byteOffset, b.length / 4); };

try {
  const material = args.material;
  const cellParam = args.cell ? `&cell=${encodeURIComponent(args.cell)}` : '';
  const page = await openPage(`${base}/web/index.html?material=${encodeURIComponent(material)}${cellParam}&three=/three/&size=${size}`);
  await page.eval(helpers);
  const light = [0.45, 0.55, 0.7];
  const info = await page.eval(`({ revision: window.measuredBrdf.THREE.REVISION,
    isData3D: window.measuredBrdf.texture.isData3DTexture,
    type: window.measuredBrdf.texture.type, format: window.measuredBrdf.texture.format,
    minFilter: window.measuredBrdf.texture.minFilter, linear: window.measuredBrdf.THREE.LinearFilter,
    size: [window.measuredBrdf.texture.image.width, window.measuredBrdf.texture.image.height, window.measuredBrdf.texture.image.depth],
    webgl2: window.measuredBrdf.renderer.capabilities.isWebGL2 !== false,
    camera: window.measuredBrdf.camera.position.toArray(),
    renderer: (() => { const gl = window.measuredBrdf.renderer.getContext(); const e = gl.getExtension('WEBGL_debug_renderer_info'); return e ? gl.getParameter(e.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER); })() })`);
  const image = fromBase64(await page.eval(`window.measuredBrdf.renderSphere(${size}, ${JSON.stringify(light)})`));
  // Rows come bottom first from readPixels; store top first.
  const flipped = new Float32Array(image.length);
  for (let y = 0; y < size; y++) flipped.set(image.subarray((size - 1 - y) * size * 4, (size - y) * size * 4), y * size * 4);
  writeFileSync(join(outDir, 'image.f32'), Buffer.from(flipped.buffer));
  writeFileSync(join(outDir, 'image.json'), JSON.stringify({
    width: size, height: size, channels: 4, rows: 'top first', light_direction: light,
    light_color: [1, 1, 1], exposure: 1, camera: { fov_y_deg: 30, position: info.camera, target: [0, 0, 0] },
    sphere: { radius: 1, centre: [0, 0, 0] }, three_revision: info.revision, texture: info }, null, 2));

  // Probe texels: texelFetch and a filtered fetch at the texel centre.
  const manifest = JSON.parse(readFileSync(join(webDir, `${material}.manifest.json`), 'utf8'));
  const probes = manifest.probe_texels;
  const n = probes.length;
  const idx = new Float32Array(n * 4);
  probes.forEach((p, i) => idx.set([p.index[0], p.index[1], p.index[2], 0], i * 4));
  const probeShader = (filtered) => `
    uniform highp sampler3D lut; uniform highp sampler2D indices;
    layout(location = 0) out highp vec4 fragColor;
    void main() {
      ivec3 i = ivec3(texelFetch(indices, ivec2(int(gl_FragCoord.x), 0), 0).xyz + 0.25);
      vec3 size = vec3(textureSize(lut, 0));
      fragColor = vec4(${filtered ? 'textureLod(lut, (vec3(i) + 0.5) / size, 0.0).rgb' : 'texelFetch(lut, i, 0).rgb'}, 1.0);
    }`;
  const probeRun = async (filtered) => fromBase64(await page.eval(`(() => { const M = window.measuredBrdf;
      const idx = new Float32Array(${JSON.stringify(Array.from(idx))});
      const t = M.dataTexture(idx, ${n}, 1);
      return M.toBase64(M.runFragment(${JSON.stringify(probeShader(filtered))}, { lut: { value: M.texture }, indices: { value: t } }, ${n}, 1)); })()`));
  const fetched = await probeRun(false), filtered = await probeRun(true);
  writeFileSync(join(outDir, 'probes.json'), JSON.stringify(probes.map((p, i) => ({
    index: p.index, manifest: p.rgb,
    texel_fetch: Array.from(fetched.subarray(i * 4, i * 4 + 3)),
    filtered_at_centre: Array.from(filtered.subarray(i * 4, i * 4 + 3)) })), null, 1));

  // Direction pairs through every shipped shader: the GLSL of the three.js module (as
  // MeasuredBrdfCell and as MeasuredBrdfTangent), the sidecar's texel_convention.glsl, and the
  // GLSL ES sources made from the other shaders (--es-harness), for the random pairs (--pairs)
  // and the exact ones (--exact).
  const readRows = (file) => readFileSync(file, 'utf8').split('\n').map((l) => l.trim())
    .filter((l) => l && !l.startsWith('#')).map((l) => l.split(/\s+/).map(Number));
  const pairSets = [['pairs', args.pairs], ['exact', args.exact]].filter(([, f]) => f);
  if (pairSets.length) {
    const glslMain = `
      uniform highp sampler3D lut; uniform highp sampler2D pairs;
      layout(location = 0) out highp vec4 fragColor;
      void main() {
        int x = int(gl_FragCoord.x);
        vec3 n = texelFetch(pairs, ivec2(x, 0), 0).xyz, l = texelFetch(pairs, ivec2(x, 1), 0).xyz,
             v = texelFetch(pairs, ivec2(x, 2), 0).xyz;
        fragColor = vec4(MeasuredBrdfCell(lut, vec2(0.0), n, l, v), 1.0);
      }`;
    // The tangent-space entry point, with l and v expressed in a tangent basis of n other than
    // the light's: MeasuredBrdfTangent must find the light's frame itself. For the random pairs
    // an arbitrary basis; for the exact ones the basis MeasuredBrdfCell falls back to (the
    // world x axis projected, y when |n.x| > 0.7), which is the exact frames' own x axis, so a
    // light on the normal keeps the azimuth reference `brdf eval` uses.
    const tangentMain = (exact) => glslMain.replace('fragColor = vec4(MeasuredBrdfCell(lut, vec2(0.0), n, l, v), 1.0);', `
        ${exact ? 'vec3 t = normalize((abs(n.x) > 0.7 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0)) - n * (abs(n.x) > 0.7 ? n.y : n.x));'
                : 'vec3 t = normalize(abs(n.z) < 0.9 ? cross(n, vec3(0.0, 0.0, 1.0)) : cross(n, vec3(1.0, 0.0, 0.0)));'}
        vec3 b = cross(n, t);
        vec3 l_ts = vec3(dot(l, t), dot(l, b), dot(l, n)), v_ts = vec3(dot(v, t), dot(v, b), dot(v, n));
        fragColor = vec4(MeasuredBrdfTangent(lut, vec2(0.0), l_ts, v_ts), 1.0);`);
    // GLSL ES sources with their own main (spirv-cross output, the translated Godot shader):
    // drop a #version line (three writes its own); the first sampler3D is the LUT, the first
    // sampler2D the pairs.
    const harnesses = (args['es-harness'] || '').split(',').filter((x) => x).map((item) => {
      const [name, file] = item.split('=');
      const src = readFileSync(file, 'utf8').replace(/^#version.*\n/, '');
      const s3 = src.match(/uniform\s+(?:highp\s+)?sampler3D\s+(\w+);/);
      // (the pairs: the one named so when there is one; the Godot shader declares its IBL pack's
      // sampler2D before the harness's)
      const s2 = src.match(/uniform\s+(?:highp\s+)?sampler2D\s+(\w*pairs\w*);/) ||
                 src.match(/uniform\s+(?:highp\s+)?sampler2D\s+(\w+);/);
      if (!s3 || !s2) throw new Error(`${file}: no sampler3D/sampler2D uniforms:\n` + src);
      // Other samplers (the Godot shader's IBL pack and radiance cube map) get a texture of
      // their own type: two sampler types on one texture unit make WebGL refuse the draw.
      const extra = [...src.matchAll(/uniform\s+(?:highp\s+)?(sampler2D|samplerCube)\s+(\w+);/g)]
        .filter((m) => m[2] !== s2[1]).map((m) => [m[2], m[1]]);
      return [name, src, s3[1], s2[1], extra];
    });
    const sidecar = args.sidecar ? JSON.parse(readFileSync(args.sidecar, 'utf8')).texel_convention.glsl : null;
    for (const [prefix, file] of pairSets) {
      const rows = readRows(file);
      const count = rows.length;
      const data = new Float32Array(count * 3 * 4);
      rows.forEach((r, i) => {
        for (let k = 0; k < 3; k++) data.set([r[3 * k], r[3 * k + 1], r[3 * k + 2], 0], (k * count + i) * 4);
      });
      const runPairs = async (source, lutName, pairsName, extra = []) => fromBase64(await page.eval(`(async () => {
          const M = window.measuredBrdf;
          const mod = await import('${base}/web/${manifest.engines.web.files.shader}');
          const source = ${JSON.stringify(source)}.replace('@MEASURED_BRDF_GLSL@', mod.MEASURED_BRDF_GLSL);
          const t = M.dataTexture(new Float32Array(${JSON.stringify(Array.from(data))}), ${count}, 3);
          const uniforms = { ${lutName}: { value: M.texture }, ${pairsName}: { value: t } };
          for (const [name, type] of ${JSON.stringify(extra)})
            uniforms[name] = { value: type === 'samplerCube' ? new M.THREE.WebGLCubeRenderTarget(4).texture
                                                             : M.dataTexture(new Float32Array(4), 1, 1) };
          return M.toBase64(M.runFragment(source, uniforms, ${count}, 1)); })()`));
      const format = (out) => Array.from({ length: count }, (_, i) =>
        `${out[i * 4]} ${out[i * 4 + 1]} ${out[i * 4 + 2]}`).join('\n') + '\n';
      const write = async (lang, source, lutName, pairsName, extra) =>
        writeFileSync(join(outDir, `${prefix}_${lang}.txt`), format(await runPairs(source, lutName, pairsName, extra)));
      await write('glsl', '@MEASURED_BRDF_GLSL@' + glslMain, 'lut', 'pairs');
      await write('tangent', '@MEASURED_BRDF_GLSL@' + tangentMain(prefix === 'exact'), 'lut', 'pairs');
      // The sidecar's snippet starts with its precision statements, as it ships.
      if (sidecar) await write('sidecar', sidecar + glslMain, 'lut', 'pairs');
      for (const [name, src, s3, s2, extra] of harnesses) await write(name, src, s3, s2, extra);
    }
  }

  // What a person sees: the sRGB viewer, after moving the light once (as a drag would).
  await page.eval(`(() => { const M = window.measuredBrdf; M.renderer.setSize(${size}, ${size});
      M.light.set(-0.5, 0.4, 0.77).normalize(); M.draw(); return true; })()`);
  const shot = await send('Page.captureScreenshot', { format: 'png', clip: { x: 0, y: 0, width: size, height: size, scale: 1 } }, page.sessionId);
  writeFileSync(join(outDir, 'screenshot.png'), Buffer.from(shot.data, 'base64'));

  if (args.bench) {
    const bench = await openPage(`${base}/web/index.html?material=${encodeURIComponent(material)}&three=/three/&size=1024`);
    // The measured material and, as the baseline in the same run, three's own
    // MeshStandardMaterial under one DirectionalLight on the same sphere, alternating.
    const result = await bench.eval(`(() => {
      const M = window.measuredBrdf, THREE = M.THREE, gl = M.renderer.getContext(), px = new Uint8Array(4);
      const standard = new THREE.MeshStandardMaterial({ color: 0x8090a0, roughness: 0.35, metalness: 0 });
      const sun = new THREE.DirectionalLight(0xffffff, 3);
      sun.position.copy(M.light);
      const frame = (material) => {
        M.sphere.material = material;
        if (material === standard) M.scene.add(sun); else M.scene.remove(sun);
        const t0 = performance.now();
        M.renderer.render(M.scene, M.camera);
        gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
        return performance.now() - t0;
      };
      for (let i = 0; i < 3; i++) { frame(M.shader); frame(standard); }
      const measured = [], baseline = [];
      for (let i = 0; i < 21; i++) { measured.push(frame(M.shader)); baseline.push(frame(standard)); }
      M.sphere.material = M.shader; M.scene.remove(sun);
      const stats = (t) => { t.sort((a, b) => a - b); return { median_ms: t[t.length >> 1], min_ms: t[0], max_ms: t[t.length - 1] }; };
      return { canvas: [gl.drawingBufferWidth, gl.drawingBufferHeight], frames: measured.length,
               measured_brdf: stats(measured), mesh_standard_material: stats(baseline) };
    })()`);
    writeFileSync(join(outDir, 'bench.json'), JSON.stringify(result, null, 2));
  }
  console.log(JSON.stringify({ ok: true, three: info.revision, renderer: info.renderer, probes: n }));
  cleanup();
} catch (e) {
  fail(`${e.stack || e}\n${consoleLines.join('\n')}`);
}
