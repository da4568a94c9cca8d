// Image-based lighting of the exported web hand-off in real headless Chromium (WebGL 2 on
// SwiftShader), for the independent checks of tests/engines/ibl_browser_test.py. three.js's own
// PMREMGenerator prefilters the equirectangular map (--env, an EXR read by three's EXRLoader);
// the shipped module (createMeasuredBrdfMaterial with `environment` and the pack texture of
// loadMeasuredBrdfIblPack) shades a sphere into an RGBA32F target read back with readPixels.
//
// World frame: the CPU preview's (docs/preview.md: z up, camera on +x, map top row = zenith,
// azimuth 0 at the left edge growing to the right) mapped into three's (y up, its
// equirectangular convention) by (x, y, z)_preview -> (-x, z, -y)_three, a reflection: the
// image comes out mirrored left-right, which the checker undoes (an isotropic BRDF under the
// mirrored map gives the mirrored picture). Orthographic camera on the preview's +x axis (the
// module takes one view direction for all pixels of an orthographic camera), the unit sphere's
// diameter covering 0.9 of the frame.
//
// Writes into --out, per material NAME (or ATLAS:CELL, written ATLAS.CELL; rows top first,
// RGBA float32, not mirrored back):
//   NAME.ibl.f32       the probe term alone (no direct light)
//   NAME.alpha110.f32  the same with every alpha_eq of the pack and broad_alpha 10 % larger
//                      (broad_alpha at most 1; mutation)
//   NAME.noE.f32       the same with the weights divided by E = D + S (mutation: E dropped)
//                      (the two mutations only for the materials of --mutate, default all)
//   NAME.furnace.f32   under a uniform radiance 1 (three's PMREM of a constant map)
// and with --standard R,G,B,METALNESS,ROUGHNESS: standard.f32, three's MeshStandardMaterial
// lit by the same PMREM (scene.environment), plus info.json (renderer, timings, PMREM size).
// With --viewer NAME: viewer.png, a screenshot of the shipped index.html in a 512 x 512 window
// (?material=NAME&env=furnace&ibl=1&lights=0&tonemap=linear&background=0) once its title is
// "ready". With --bench: bench.json, frame times of the measured material and MeshStandardMaterial
// under the same environment at --bench-size, alternating.
// All materials are rendered by one page in one browser (one PMREM of the map and of the furnace).
// Usage: node render_ibl.mjs --web DIR --materials A,B,ATLAS:CELL,... --env FILE.exr --out DIR
//        [--size N] [--mutate A,B,...] [--standard r,g,b,m,ro] [--viewer NAME] [--bench]
//        [--bench-size N] [--chromium PATH] [--timeout-s S (default 180)]
import { writeFileSync, existsSync } from 'node:fs';
import { join, resolve, dirname, basename } from 'node:path';
import { fileURLToPath } from 'node:url';
import { parseOptions, serveFolders, startChromium } from './headless_chromium.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const args = parseOptions(process.argv.slice(2));
for (const required of ['web', 'materials', 'env', 'out'])
  if (!args[required]) { console.error(`render_ibl: --${required} is required`); process.exit(2); }
const webDir = resolve(args.web), outDir = resolve(args.out), envFile = resolve(args.env);
const threeDir = resolve(here, 'node_modules/three');
if (!existsSync(join(threeDir, 'build/three.module.js'))) {
  console.error('render_ibl: three is not installed in tests/node; run tools/install-npm-deps.sh');
  process.exit(1);
}
const size = parseInt(args.size || '128', 10);
const materials = args.materials.split(',').filter((m) => m);
const mutate = args.mutate ? new Set(args.mutate.split(',').filter((m) => m)) : null;
const deadline = Date.now() + 1000 * parseFloat(args['timeout-s'] || '180');

const page = `<!DOCTYPE html><html><head><meta charset="utf-8">
<script type="importmap">{"imports": {"three": "/three/build/three.module.js", "three/addons/": "/three/examples/jsm/"}}</script>
</head><body><script type="module">
import * as THREE from 'three';
import { EXRLoader } from 'three/addons/loaders/EXRLoader.js';
window.THREE = THREE;
window.EXRLoader = EXRLoader;
window.iblReady = true;
</script></body></html>`;

const { server, base } = await serveFolders(
  { '/web/': webDir, '/three/': threeDir, '/env/': dirname(envFile) }, { '/ibl.html': page });
const { send, fail, cleanup, consoleLines } = await startChromium({ chromium: args.chromium || 'chromium', name: 'render_ibl', deadline, server });
const sleep = (ms) => new Promise((ok) => setTimeout(ok, ms));

const { targetId } = await send('Target.createTarget', { url: 'about:blank' });
const { sessionId } = await send('Target.attachToTarget', { targetId, flatten: true });
await send('Runtime.enable', {}, sessionId);
await send('Page.navigate', { url: `${base}/ibl.html` }, sessionId);
const evaluate = async (expression) => {
  const r = await send('Runtime.evaluate', { expression, awaitPromise: true, returnByValue: true }, sessionId);
  if (r.exceptionDetails)
    throw new Error(`${r.exceptionDetails.exception?.description || r.exceptionDetails.text}\n${consoleLines.join('\n')}`);
  return r.result.value;
};
for (;;) {
  if (Date.now() > deadline) fail('the page never loaded three.js');
  if (await evaluate('window.iblReady === true')) break;
  await sleep(100);
}
const fromBase64 = (s) => { const b = Buffer.from(s, 'base64'); return new Float32Array(b.buffer, b.byteOffset, b.length / 4); };

try {
  const setup = await evaluate(`(async () => {
    const THREE = window.THREE, size = ${size};
    const renderer = new THREE.WebGLRenderer({ antialias: false });
    renderer.setPixelRatio(1);
    renderer.setSize(size, size);
    const t0 = performance.now();
    const exr = await new window.EXRLoader().setDataType(THREE.FloatType).loadAsync('/env/${basename(envFile)}');
    exr.mapping = THREE.EquirectangularReflectionMapping;
    const pmrem = new THREE.PMREMGenerator(renderer);
    const env = pmrem.fromEquirectangular(exr).texture;
    const t1 = performance.now();
    const ones = new THREE.DataTexture(new Float32Array(64 * 32 * 4).fill(1), 64, 32, THREE.RGBAFormat, THREE.FloatType);
    ones.mapping = THREE.EquirectangularReflectionMapping;
    ones.needsUpdate = true;
    const furnace = pmrem.fromEquirectangular(ones).texture;
    const h = 1 / 0.9;
    const camera = new THREE.OrthographicCamera(-h, h, h, -h, 5, 15);
    camera.position.set(-10, 0, 0);  // the preview's +x axis
    camera.up.set(0, 1, 0);            // the preview's +z
    camera.lookAt(0, 0, 0);
    const scene = new THREE.Scene();
    const sphere = new THREE.Mesh(new THREE.SphereGeometry(1, 384, 192));
    scene.add(sphere);
    const target = new THREE.WebGLRenderTarget(size, size, { type: THREE.FloatType, format: THREE.RGBAFormat,
        minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter });
    const toBase64 = (floats) => {
      const bytes = new Uint8Array(floats.buffer);
      let s = '';
      for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode.apply(null, bytes.subarray(i, i + 0x8000));
      return btoa(s);
    };
    // Renders the scene into the float target; rows top first.
    const render = (material) => {
      sphere.material = material;
      renderer.setRenderTarget(target);
      renderer.render(scene, camera);
      renderer.setRenderTarget(null);
      const b = new Float32Array(size * size * 4);
      renderer.readRenderTargetPixels(target, 0, 0, size, size, b);
      const top = new Float32Array(b.length);
      for (let y = 0; y < size; y++) top.set(b.subarray((size - 1 - y) * size * 4, (size - y) * size * 4), y * size * 4);
      return toBase64(top);
    };
    window.ibl = { THREE, renderer, env, furnace, scene, render, camera };
    return { pmrem_ms: t1 - t0, env_size: env.image.width ?? env.source.data?.width ?? null,
             env_levels: env.mipmaps.length, revision: THREE.REVISION,
             renderer: (() => { const gl = renderer.getContext(); const e = gl.getExtension('WEBGL_debug_renderer_info'); return e ? gl.getParameter(e.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER); })() };
  })()`);
  const timings = {};
  for (const entry of materials) {
    // NAME, or ATLAS:CELL (a material of an atlas: its cell origin and its row of the pack).
    const [name, cellName] = entry.split(':');
    const t0 = Date.now();
    const renders = await evaluate(`(async () => {
      const { THREE, env, furnace, render } = window.ibl;
      const manifest = await fetch('/web/${name}.manifest.json').then((r) => r.json());
      const mod = await import('/web/' + manifest.engines.web.files.shader);
      const lut = await mod.loadMeasuredBrdfTexture('/web/${name}.ktx2', window.ibl.renderer);
      const pack = await mod.loadMeasuredBrdfIblPack('/web/' + manifest.ibl.texture.file);
      let cell = [0, 0], ibl = manifest.ibl;
      if (manifest.atlas) {
        const m = manifest.cells.findIndex((c) => c.material === ${JSON.stringify(cellName ?? '')});
        if (m < 0) throw new Error('${entry}: no such cell');
        cell = [manifest.cells[m].x0, manifest.cells[m].y0];
        ibl = manifest.ibl.cells[m];
      }
      const row = ibl.row, q = ibl.diffuse_quadratic_rgb;
      // broadScale: the broad lobe's broad_alpha times this (at most 1), for the mutation.
      const material = (environment, iblPack, broadScale = 1) => mod.createMeasuredBrdfMaterial(lut, {
          lightColor: new THREE.Vector3(0, 0, 0), encodeSrgb: false, environment, iblPack,
          iblPackRow: row, iblDiffuse: q, iblBroadAlpha: Math.min(1, (ibl.broad_alpha ?? 1) * broadScale), cell });
      // A copy of the pack (texels (specular_rgb, alpha_eq) at mu_i) changed by f(values, D_fit(mu_i)).
      const mutated = (f) => {
        const w = pack.image.width, src = pack.image.data, data = new Uint16Array(src.length);
        for (let t = 0; t < src.length / 4; t++) {
          const s = 1 - ((t % w) + 0.5) / w;
          const d = [0, 1, 2].map((c) => q[0][c] + s * (q[1][c] + s * q[2][c]));
          const vals = [0, 1, 2, 3].map((c) => THREE.DataUtils.fromHalfFloat(src[4 * t + c]));
          const out = f(vals, d);
          for (let c = 0; c < 4; c++) data[4 * t + c] = THREE.DataUtils.toHalfFloat(out[c]);
        }
        const t = new THREE.DataTexture(data, w, pack.image.height, THREE.RGBAFormat, THREE.HalfFloatType);
        t.minFilter = t.magFilter = THREE.LinearFilter; t.generateMipmaps = false; t.needsUpdate = true;
        return t;
      };
      const alpha110 = mutated((v) => [v[0], v[1], v[2], v[3] * 1.1]);
      // E dropped: the specular weight made 1 - D_fit, so D_fit + S = 1 at every mu_i.
      const noE = mutated((v, d) => [1 - d[0], 1 - d[1], 1 - d[2], v[3]]);
      const out = { ibl: render(material(env, pack)), furnace: render(material(furnace, pack)) };
      if (${mutate === null || mutate.has(entry)})
        Object.assign(out, { alpha110: render(material(env, alpha110, 1.1)), noE: render(material(env, noE)) });
      for (const t of [lut, pack, alpha110, noE]) t.dispose();  // 37 materials in one page
      return out;
    })()`);
    const stem = entry.replace(':', '.');
    for (const [k, v] of Object.entries(renders)) writeFileSync(join(outDir, `${stem}.${k}.f32`), Buffer.from(fromBase64(v).buffer));
    timings[entry] = Date.now() - t0;
  }
  if (args.standard) {
    const [r, g, b, metalness, roughness] = args.standard.split(',').map(Number);
    const s = await evaluate(`(() => {
      const { THREE, env, scene, render } = window.ibl;
      scene.environment = env;
      const m = new THREE.MeshStandardMaterial({ metalness: ${metalness}, roughness: ${roughness} });
      m.color.setRGB(${r}, ${g}, ${b}, THREE.LinearSRGBColorSpace);
      const out = render(m);
      scene.environment = null;
      return out;
    })()`);
    writeFileSync(join(outDir, 'standard.f32'), Buffer.from(fromBase64(s).buffer));
  }
  if (args.bench) {
    const n = parseInt(args['bench-size'] || '1024', 10);
    const bench = await evaluate(`(async () => {
      const { THREE, env, scene, camera, renderer } = window.ibl;
      const name = ${JSON.stringify(materials[0])};
      const manifest = await fetch('/web/' + name + '.manifest.json').then((r) => r.json());
      const mod = await import('/web/' + manifest.engines.web.files.shader);
      const lut = await mod.loadMeasuredBrdfTexture('/web/' + name + '.ktx2', renderer);
      const pack = await mod.loadMeasuredBrdfIblPack('/web/' + manifest.ibl.texture.file);
      const measured = mod.createMeasuredBrdfMaterial(lut, { encodeSrgb: false, environment: env, iblPack: pack,
          iblDiffuse: manifest.ibl.diffuse_quadratic_rgb, iblBroadAlpha: manifest.ibl.broad_alpha,
          lightDirection: new THREE.Vector3(-0.5, 0.7, 0.5) });
      const standard = new THREE.MeshStandardMaterial({ metalness: 1, roughness: 0.39 });
      const sun = new THREE.DirectionalLight(0xffffff, 3);
      sun.position.set(-0.5, 0.7, 0.5);
      renderer.setSize(${n}, ${n});
      const gl = renderer.getContext(), px = new Uint8Array(4), sphere = scene.children[0];
      const frame = (material) => {
        sphere.material = material;
        scene.environment = material === standard ? env : null;
        if (material === standard) scene.add(sun); else scene.remove(sun);
        const t0 = performance.now();
        renderer.render(scene, camera);
        gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
        return performance.now() - t0;
      };
      for (let i = 0; i < 3; i++) { frame(measured); frame(standard); }
      const a = [], b = [];
      for (let i = 0; i < 15; i++) { a.push(frame(measured)); b.push(frame(standard)); }
      scene.remove(sun); scene.environment = null;
      const stats = (t) => { t.sort((x, y) => x - y); return { median_ms: t[t.length >> 1], min_ms: t[0], max_ms: t[t.length - 1] }; };
      return { canvas: [${n}, ${n}], frames: a.length, lights: 'the environment (PMREM) and one directional light',
               measured_brdf: stats(a), mesh_standard_material: stats(b) };
    })()`);
    writeFileSync(join(outDir, 'bench.json'), JSON.stringify(bench, null, 2));
  }
  // The shipped viewer as a person opens it, in a 512 x 512 window: furnace, probes only,
  // linear tone map, no background; a screenshot once document.title says "ready".
  let viewer = null;
  if (args.viewer) {
    const t = await send('Target.createTarget', { url: 'about:blank' });
    const v = await send('Target.attachToTarget', { targetId: t.targetId, flatten: true });
    await send('Emulation.setDeviceMetricsOverride', { width: 512, height: 512, deviceScaleFactor: 1, mobile: false }, v.sessionId);
    await send('Runtime.enable', {}, v.sessionId);
    const query = `material=${encodeURIComponent(args.viewer)}&env=furnace&ibl=1&lights=0&tonemap=linear&background=0&three=/three/`;
    await send('Page.navigate', { url: `${base}/web/index.html?${query}` }, v.sessionId);
    let title = '';
    for (;;) {
      if (Date.now() > deadline) fail(`viewer: document.title stayed "${title}"\n${consoleLines.join('\n')}`);
      title = (await send('Runtime.evaluate', { expression: 'document.title', returnByValue: true }, v.sessionId)).result.value;
      if (title === 'ready' || title === 'error') break;
      await sleep(100);
    }
    if (title !== 'ready') fail(`viewer: document.title "${title}"\n${consoleLines.join('\n')}`);
    const shot = await send('Page.captureScreenshot', { format: 'png' }, v.sessionId);
    writeFileSync(join(outDir, 'viewer.png'), Buffer.from(shot.data, 'base64'));
    viewer = { query, title };
  }
  writeFileSync(join(outDir, 'info.json'), JSON.stringify({ ...setup, size, material_ms: timings, viewer }, null, 2));
  console.log(JSON.stringify({ ok: true, ...setup, material_ms: timings }));
  cleanup();
} catch (e) {
  fail(`${e.stack || e}\n${consoleLines.join('\n')}`);
}
