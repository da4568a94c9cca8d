// Validates brdf-toolchain's KTX2 output with an independent parser, ktx-parse (npm), and
// checks what ktx-parse does not validate itself (the Data Format Descriptor, alignment,
// texel values, checksum) against values written out here from the specifications:
//   KTX 2.0 specification (Khronos), Khronos Data Format Specification 1.3, and the
//   E5B9G9R9 descriptor libktx requires (KTX-Software lib/texture2.c).
// Usage: node check_ktx2.mjs WRITER [OUT_DIR]  (WRITER = the write_ktx2_fixture executable;
// without OUT_DIR the files go to a new private folder under the system's temporary folder)
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdirSync, mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import test from 'node:test';
import { read, write } from 'ktx-parse';

const [writer, givenDir] = process.argv.slice(2);
if (!writer) {
  console.error('usage: node check_ktx2.mjs WRITER [OUT_DIR]');
  process.exit(2);
}
const outDir = givenDir ?? mkdtempSync(join(tmpdir(), 'brdf-ktx-parse-'));
if (givenDir) rmSync(outDir, { recursive: true, force: true });
mkdirSync(outDir, { recursive: true });
if (!givenDir) process.on('exit', () => rmSync(outDir, { recursive: true, force: true }));
execFileSync(writer, [outDir], { stdio: 'inherit' });

const KHR_DF_SAMPLE_DATATYPE_EXPONENT = 0x20;

function load(name) {
  const buf = readFileSync(`${outDir}/${name}`);
  const bytes = new Uint8Array(buf.buffer, buf.byteOffset, buf.byteLength);
  return { bytes, view: new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength), ktx: read(bytes) };
}

function text(value) {
  const s = typeof value === 'string' ? value : new TextDecoder().decode(value);
  return s.endsWith('\0') ? s.slice(0, -1) : s;
}

// RGB9E5 decode written from EXT_texture_shared_exponent: c = c_s · 2^(exp − 15 − 9).
function decode(word) {
  const scale = 2 ** ((word >>> 27) - 24);
  return [(word & 0x1ff) * scale, ((word >>> 9) & 0x1ff) * scale, ((word >>> 18) & 0x1ff) * scale];
}

function crc32(bytes) {
  let crc = 0xffffffff;
  for (const b of bytes) {
    crc ^= b;
    for (let k = 0; k < 8; k++) crc = (crc >>> 1) ^ (0xedb88320 & -(crc & 1));
  }
  return (crc ^ 0xffffffff) >>> 0;
}

function checkContainer(ktx, width, height, depth) {
  assert.equal(ktx.vkFormat, 123, 'vkFormat VK_FORMAT_E5B9G9R9_UFLOAT_PACK32');
  assert.equal(ktx.typeSize, 4);
  assert.equal(ktx.pixelWidth, width);
  assert.equal(ktx.pixelHeight, height);
  assert.equal(ktx.pixelDepth, depth);
  assert.equal(ktx.layerCount, 0);
  assert.equal(ktx.faceCount, 1);
  assert.equal(ktx.levelCount, 1);
  assert.equal(ktx.supercompressionScheme, 0);
  assert.equal(ktx.levels.length, 1);
  assert.equal(ktx.levels[0].levelData.byteLength, width * height * depth * 4);
  assert.equal(Number(ktx.levels[0].uncompressedByteLength), width * height * depth * 4);
}

function checkDfd(ktx, view) {
  assert.equal(ktx.dataFormatDescriptor.length, 1);
  const dfd = ktx.dataFormatDescriptor[0];
  assert.equal(dfd.vendorId, 0, 'KHR_DF_VENDORID_KHRONOS');
  assert.equal(dfd.descriptorType, 0, 'KHR_DF_KHR_DESCRIPTORTYPE_BASICFORMAT');
  assert.equal(dfd.versionNumber, 2, 'KHR_DF_VERSIONNUMBER_1_3');
  // ktx-parse derives the sample count from descriptorBlockSize; read the field itself too.
  const dfdOffset = view.getUint32(48, true);
  assert.equal(view.getUint16(dfdOffset + 4 + 6, true), 24 + 6 * 16, 'descriptorBlockSize');
  assert.equal(dfd.colorModel, 1, 'KHR_DF_MODEL_RGBSDA');
  assert.equal(dfd.colorPrimaries, 1, 'KHR_DF_PRIMARIES_BT709');
  assert.equal(dfd.transferFunction, 1, 'KHR_DF_TRANSFER_LINEAR');
  assert.equal(dfd.flags, 0, 'KHR_DF_FLAG_ALPHA_STRAIGHT');
  assert.deepEqual(dfd.texelBlockDimension, [0, 0, 0, 0]);
  assert.deepEqual(dfd.bytesPlane, [4, 0, 0, 0, 0, 0, 0, 0]);
  // Per channel: a 9-bit mantissa (stored bitLength 8) and the shared 5-bit exponent at bit 27
  // (stored 4) with the EXPONENT qualifier, sampleLower = bias 15, sampleUpper = 31.
  const expected = [];
  for (const [channel, offset] of [[0, 0], [1, 9], [2, 18]]) {
    expected.push({ bitOffset: offset, bitLength: 8, channelType: channel, samplePosition: [0, 0, 0, 0], sampleLower: 0, sampleUpper: 8448 });
    expected.push({ bitOffset: 27, bitLength: 4, channelType: channel | KHR_DF_SAMPLE_DATATYPE_EXPONENT, samplePosition: [0, 0, 0, 0], sampleLower: 15, sampleUpper: 31 });
  }
  assert.deepEqual(dfd.samples, expected);
}

function checkLayout(view, bytes) {
  // Index fields read straight from the header (KTX 2.0 §3): DFD right after the level index,
  // key/value data right after the DFD, level 0 4-byte aligned after the key/value data.
  const dfdOffset = view.getUint32(48, true), dfdLength = view.getUint32(52, true);
  const kvdOffset = view.getUint32(56, true), kvdLength = view.getUint32(60, true);
  const levelOffset = Number(view.getBigUint64(80, true)), levelLength = Number(view.getBigUint64(88, true));
  assert.equal(dfdOffset, 80 + 24);
  assert.equal(view.getUint32(dfdOffset, true), dfdLength, 'dfdTotalSize');
  assert.equal(kvdOffset, dfdOffset + dfdLength);
  assert.equal(kvdOffset % 4, 0);
  assert.equal(levelOffset % 4, 0, 'level aligned to lcm(texel block size, 4)');
  assert.ok(levelOffset - (kvdOffset + kvdLength) < 4, 'no more than mipPadding');
  assert.equal(levelOffset + levelLength, bytes.byteLength);
  return { levelOffset, levelLength };
}

test('single LUT: container, DFD, metadata, texels and checksum', () => {
  const { bytes, view, ktx } = load('ramp.ktx2');
  checkContainer(ktx, 361, 181, 4);
  checkDfd(ktx, view);
  const { levelOffset, levelLength } = checkLayout(view, bytes);
  const keys = Object.keys(ktx.keyValue);
  assert.deepEqual([...keys].sort(), keys.slice().sort());
  assert.match(text(ktx.keyValue.KTXwriter), /^brdf-toolchain \d+\.\d+\.\d+$/);
  assert.equal(text(ktx.keyValue.KTXorientation), 'rdi');
  const sidecar = JSON.parse(text(ktx.keyValue['brdf.sidecar']));
  assert.deepEqual(sidecar.theta_in_deg, [0, 20, 40, 60]);
  assert.equal(sidecar.grid.width, 361);
  assert.equal(sidecar.payload.bytes, levelLength);

  const level = ktx.levels[0].levelData;
  const words = new DataView(level.buffer, level.byteOffset, level.byteLength);
  for (let k = 0; k < 4; k++)
    for (let j = 0; j < 181; j++)
      for (let i = 0; i < 361; i++) {
        const n = (k * 181 + j) * 361 + i;
        assert.deepEqual(decode(words.getUint32(4 * n, true)), [i, j, 100 * k], `texel ${i},${j},${k}`);
      }
  const crc = crc32(bytes.subarray(levelOffset, levelOffset + levelLength));
  const hex = '0x' + crc.toString(16).padStart(8, '0');
  assert.equal(sidecar.payload.checksum.value, hex);
  assert.equal(JSON.parse(readFileSync(`${outDir}/ramp.json`, 'utf8')).payload.checksum.value, hex);
});

test('atlas: three materials in a 2 × 2 cell grid', () => {
  const { bytes, view, ktx } = load('atlas.ktx2');
  checkContainer(ktx, 2 * 361, 2 * 181, 4);
  checkDfd(ktx, view);
  checkLayout(view, bytes);
  const manifest = JSON.parse(text(ktx.keyValue['brdf.atlas']));
  assert.deepEqual(manifest.materials.map((m) => m.name), ['ramp0', 'ramp1', 'ramp2']);
  const level = ktx.levels[0].levelData;
  const words = new DataView(level.buffer, level.byteOffset, level.byteLength);
  const width = 722, height = 362;
  for (let m = 0; m < 4; m++) {
    const x0 = (m % 2) * 361, y0 = Math.floor(m / 2) * 181;
    if (m < 3) assert.deepEqual([manifest.materials[m].cell.x0, manifest.materials[m].cell.y0], [x0, y0]);
    for (let k = 0; k < 4; k++)
      for (let j = 0; j < 181; j += 12)
        for (let i = 0; i < 361; i += 5) {
          const n = (k * height + y0 + j) * width + x0 + i;
          const want = m < 3 ? [i, j, 100 * k + m] : [0, 0, 0];  // cell 3 is unused
          assert.deepEqual(decode(words.getUint32(4 * n, true)), want, `material ${m} texel ${i},${j},${k}`);
        }
  }
});

test("ktx-parse's own writer reproduces both files byte for byte", () => {
  // Layout, padding, key order and level placement all agree with an independent serializer.
  for (const name of ['ramp.ktx2', 'atlas.ktx2']) {
    const { bytes, ktx } = load(name);
    const again = write(ktx, { keepWriter: true });
    assert.equal(again.byteLength, bytes.byteLength, name);
    assert.ok(Buffer.from(again).equals(Buffer.from(bytes)), `${name} differs from ktx-parse's serialization`);
  }
});
