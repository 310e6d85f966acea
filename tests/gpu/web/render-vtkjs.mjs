#!/usr/bin/env node
// Renders volref scene files with vtk.js 37.4.3 in headless Chromium (issue 22; docs/gpu-checking.md).
//
//   node render-vtkjs.mjs --out DIR [--chromium /usr/bin/chromium] SCENE.json...
//
// For each scene writes DIR/NAME-vtkjs.tif: premultiplied RGBA, 32-bit float, as vtk.js left its float
// (RGBA16F) drawing buffer (NaN where vtk.js divides 0 by 0). The page (page/main.js) is bundled with
// esbuild into DIR, served on 127.0.0.1 from DIR, and driven with puppeteer-core; the packages come from
// ./node_modules (scripts/install-deps.sh runs `npm ci` here); nothing is downloaded. Any failure
// (no browser, no WebGL2, a scene this driver cannot translate) exits 1 with a one-line message.
import fs from 'node:fs';
import http from 'node:http';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));

function fail(message) {
  process.stderr.write(`render-vtkjs: ${message}\n`);
  process.exit(1);
}

// ---- the scene, as volref reads it (docs/scene-format.md), for the keys this driver supports ----
function vec3(v, what) {
  if (!Array.isArray(v) || v.length !== 3 || !v.every(Number.isFinite)) fail(`${what}: expected three numbers`);
  return v;
}

function fieldValues(src, origin, spacing) {
  const dims = vec3(src.dims, 'volume.source.dims');
  const [nx, ny, nz] = dims;
  const out = new Float32Array(nx * ny * nz);
  const ml = (i, n) => (n === 1 ? 0 : -1 + (2 * i) / (n - 1));
  for (let k = 0; k < nz; ++k)
    for (let j = 0; j < ny; ++j)
      for (let i = 0; i < nx; ++i) {
        const p = [origin[0] + i * spacing[0], origin[1] + j * spacing[1], origin[2] + k * spacing[2]];
        let v;
        switch (src.field) {
          case 'constant': v = src.value; break;
          case 'linear': { const c = src.coefficients; v = c[0] * p[0] + c[1] * p[1] + c[2] * p[2] + c[3]; break; }
          case 'radial': { const c = src.center ?? [0, 0, 0]; v = Math.hypot(p[0] - c[0], p[1] - c[1], p[2] - c[2]); break; }
          case 'gaussian': {
            const c = src.center ?? [0, 0, 0], s = src.sigma ?? 1, a = src.amplitude ?? 1;
            const d2 = (p[0] - c[0]) ** 2 + (p[1] - c[1]) ** 2 + (p[2] - c[2]) ** 2;
            v = a * Math.exp(-d2 / (2 * s * s));
            break;
          }
          case 'marschner-lobb': {
            const fm = src.fm ?? 6, alpha = src.alpha ?? 0.25;
            const x = ml(i, nx), y = ml(j, ny), z = ml(k, nz), r = Math.sqrt(x * x + y * y);
            const rho = Math.cos(2 * Math.PI * fm * Math.cos((Math.PI * r) / 2));
            v = (1 - Math.sin((Math.PI * z) / 2) + alpha * (1 + rho)) / (2 * (1 + alpha));
            break;
          }
          default: fail(`volume.source.field "${src.field}": this driver renders constant, linear, radial, gaussian and marschner-lobb fields`);
        }
        out[i + nx * (j + ny * k)] = v;
      }
  return { dims, data: out };
}

function describe(file) {
  let s;
  try { s = JSON.parse(fs.readFileSync(file, 'utf8')); } catch (e) { fail(`${file}: ${e.message}`); }
  const v = s.volume;
  if (!v || !v.source || typeof v.source !== 'object' || !v.source.field) fail(`${file}: volume.source must be a procedural field`);
  const origin = v.origin ?? [0, 0, 0], spacing = v.spacing ?? [1, 1, 1];
  const { dims, data } = fieldValues(v.source, origin, spacing);
  const t = v.transfer;
  if (!t || !Array.isArray(t.color) || !Array.isArray(t.opacity)) fail(`${file}: volume.transfer.color and .opacity are needed`);
  const sh = v.shading ? { ka: v.shading.ka ?? 0.1, kd: v.shading.kd ?? 0.7, ks: v.shading.ks ?? 0.2, n: v.shading.n ?? 10,
                           twoSided: v.shading.two_sided ?? false } : null;
  const lights = (s.lights ?? [{ type: 'headlight', color: [1, 1, 1] }]).map((l) => {
    const color = l.color ?? [1, 1, 1];
    if ((l.type ?? 'headlight') === 'headlight') return { type: 'headlight', color };
    const d = vec3(l.direction, 'lights[].direction'), n = Math.hypot(...d);
    return { type: 'directional', direction: d.map((x) => x / n), color };
  });
  const c = s.camera;
  if (!c || (c.type !== 'perspective' && c.type !== 'orthographic')) fail(`${file}: camera must be perspective or orthographic`);
  const r = s.render ?? {};
  const step = (r.step ?? 0.5) * ((r.step_units ?? 'voxel') === 'voxel' ? Math.min(...spacing) : 1);
  const img = s.image ?? {};
  return {
    width: img.width ?? 256, height: img.height ?? 256, dims, spacing, origin,
    data: Buffer.from(data.buffer).toString('base64'),
    color: t.color, opacity: t.opacity, unitDistance: t.opacity_unit_distance ?? 1, step,
    projection: r.projection ?? 'composite', jitter: r.profile_options?.jitter ?? 1, shading: sh, lights,
    camera: { type: c.type, eye: vec3(c.eye, 'camera.eye'), target: vec3(c.target, 'camera.target'),
              up: vec3(c.up ?? [0, 1, 0], 'camera.up'), fovY: c.fov_y ?? 30, height: c.height ?? 1 },
  };
}

// ---- a float RGBA TIFF (associated alpha), which volref compare reads through OpenImageIO ----
function writeFloatTiff(file, width, height, rgba) {
  const tags = [];
  const headerSize = 8;
  const nTags = 11;
  const ifdSize = 2 + nTags * 12 + 4;
  let extraOffset = headerSize + ifdSize;
  const bitsOffset = extraOffset; extraOffset += 8;
  const formatOffset = extraOffset; extraOffset += 8;
  const dataOffset = extraOffset;
  const dataBytes = width * height * 16;
  const SHORT = 3, LONG = 4;
  tags.push([256, LONG, 1, width], [257, LONG, 1, height], [258, SHORT, 4, bitsOffset], [259, SHORT, 1, 1],
            [262, SHORT, 1, 2], [273, LONG, 1, dataOffset], [277, SHORT, 1, 4], [278, LONG, 1, height],
            [279, LONG, 1, dataBytes], [338, SHORT, 1, 1], [339, SHORT, 4, formatOffset]);
  const buf = Buffer.alloc(dataOffset + dataBytes);
  buf.write('II', 0, 'latin1');
  buf.writeUInt16LE(42, 2);
  buf.writeUInt32LE(headerSize, 4);
  let o = headerSize;
  buf.writeUInt16LE(nTags, o); o += 2;
  for (const [tag, type, count, value] of tags) {
    buf.writeUInt16LE(tag, o); buf.writeUInt16LE(type, o + 2); buf.writeUInt32LE(count, o + 4);
    if (type === SHORT && count === 1) buf.writeUInt16LE(value, o + 8); else buf.writeUInt32LE(value, o + 8);
    o += 12;
  }
  buf.writeUInt32LE(0, o);
  for (let i = 0; i < 4; ++i) { buf.writeUInt16LE(32, bitsOffset + 2 * i); buf.writeUInt16LE(3, formatOffset + 2 * i); }
  Buffer.from(rgba.buffer, rgba.byteOffset, rgba.byteLength).copy(buf, dataOffset);
  fs.writeFileSync(file, buf);
}

// ---- main ----
const args = process.argv.slice(2);
let out = null, chromium = '/usr/bin/chromium';
const scenes = [];
for (let i = 0; i < args.length; ++i) {
  if (args[i] === '--out') out = args[++i];
  else if (args[i] === '--chromium') chromium = args[++i];
  else scenes.push(args[i]);
}
if (!out || scenes.length === 0) fail('usage: render-vtkjs.mjs --out DIR [--chromium PATH] SCENE.json...');
fs.mkdirSync(out, { recursive: true });
if (!fs.existsSync(path.join(here, 'node_modules', 'puppeteer-core')))
  fail(`no ${path.join(here, 'node_modules')}: run scripts/install-deps.sh (npm ci in tests/gpu/web)`);
if (!fs.existsSync(chromium)) fail(`no browser at ${chromium}: run scripts/install-deps.sh (apt-get install chromium)`);

const descriptions = scenes.map((f) => [f, describe(f)]);
const esbuild = await import('esbuild');
const puppeteer = (await import('puppeteer-core')).default;
await esbuild.build({ entryPoints: [path.join(here, 'page', 'main.js')], bundle: true, format: 'iife',
                      outfile: path.join(out, 'page.js'), logLevel: 'error', absWorkingDir: here });
fs.writeFileSync(path.join(out, 'index.html'), '<!doctype html><html><body style="margin:0"><script src="page.js"></script></body></html>');
const server = http.createServer((req, res) => {
  if (req.url === '/favicon.ico') { res.writeHead(204); res.end(); return; }
  const name = req.url === '/' ? 'index.html' : path.basename(req.url);
  const file = path.join(out, name);
  if (!['index.html', 'page.js'].includes(name) || !fs.existsSync(file)) { res.writeHead(404); res.end(); return; }
  res.writeHead(200, { 'Content-Type': name.endsWith('.js') ? 'text/javascript' : 'text/html' });
  res.end(fs.readFileSync(file));
});
await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
const url = `http://127.0.0.1:${server.address().port}/`;
let browser;
try {
  browser = await puppeteer.launch({
    executablePath: chromium,
    headless: true,
    args: ['--headless=new', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist',
           '--no-sandbox', '--disable-dev-shm-usage'],
  });
} catch (e) {
  server.close();
  fail(`cannot start ${chromium}: ${String(e.message).split('\n')[0]}`);
}
let status = 0;
try {
  const page = await browser.newPage();
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  await page.goto(url);
  await page.waitForFunction('window.pageReady === true', { timeout: 30000 });
  for (const [file, d] of descriptions) {
    const result = await page.evaluate((desc) => window.renderScene(desc), d);
    const raw = Buffer.from(result.pixels, 'base64');
    const rgba = new Float32Array(raw.buffer, raw.byteOffset, raw.byteLength / 4);
    const name = path.basename(file, '.json');
    writeFloatTiff(path.join(out, `${name}-vtkjs.tif`), d.width, d.height, rgba);
    let nonFinite = 0;
    for (const x of rgba) if (!Number.isFinite(x)) ++nonFinite;
    process.stdout.write(`${name}: ${d.width}x${d.height} ${result.info.renderer} (${result.info.drawingBufferFormat === 0x881A ? 'RGBA16F' : result.info.drawingBufferFormat}), ${nonFinite} non-finite values (channels)\n`);
  }
  if (errors.length) process.stderr.write(`render-vtkjs: page messages: ${errors.join(' | ')}\n`);
} catch (e) {
  process.stderr.write(`render-vtkjs: ${String(e.message).split('\n')[0]}\n`);
  status = 1;
} finally {
  await browser.close();
  server.close();
}
process.exit(status);
