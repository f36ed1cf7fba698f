// Opens halo4d's viewer page (`outputs.html`) in headless Chromium through playwright-core
// (both installed by .ci/run's browser step), at the size of halo4d's picture of the same
// scene, waits until the page says it drew its first frame (window.HALO4D_READY) or failed
// (window.HALO4D_ERROR), and saves a screenshot of the page without its bar.
//
//   node browser-shot.mjs PAGE.html PICTURE.png SHOT.png
//
// WebGL runs on SwiftShader, Chromium's software renderer: no GPU needed. Exit status 0 when
// the page drew its frame and the screenshot was saved; 1 otherwise (the page's error and its
// console are printed).
import { readFile } from 'node:fs/promises';
import { createRequire } from 'node:module';
import { pathToFileURL } from 'node:url';

const require = createRequire(import.meta.url);
const { chromium } = require('playwright-core');

const [page_file, picture, shot] = process.argv.slice(2);
if (!shot) {
  console.log('usage: node browser-shot.mjs PAGE.html PICTURE.png SHOT.png');
  process.exit(2);
}
// The picture's size, from its PNG header (IHDR: width and height, big-endian, at 16).
const png = await readFile(picture);
const width = png.readUInt32BE(16);
const height = png.readUInt32BE(20);

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
  args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
let status = 0;
try {
  const page = await browser.newPage({ viewport: { width, height }, deviceScaleFactor: 1 });
  const console_lines = [];
  page.on('console', (m) => console_lines.push(`[console ${m.type()}] ${m.text()}`));
  page.on('pageerror', (e) => console_lines.push(`[page error] ${e}`));
  const started = Date.now();
  await page.goto(pathToFileURL(page_file).href);
  await page.waitForFunction(() => window.HALO4D_READY || window.HALO4D_ERROR, null, { timeout: 180000 });
  const error = await page.evaluate(() => window.HALO4D_ERROR);
  if (error) {
    console.log(`${page_file}: the page failed: ${error}`);
    status = 1;
  } else {
    const renderer = await page.evaluate(() => {
      const gl = document.querySelector('canvas').getContext('webgl2');
      const info = gl && gl.getExtension('WEBGL_debug_renderer_info');
      return info ? gl.getParameter(info.UNMASKED_RENDERER_WEBGL) : 'unknown';
    });
    await page.evaluate(() => {
      document.getElementById('halo4d-bar').style.display = 'none';
    });
    await page.screenshot({ path: shot });
    const version = browser.version();
    console.log(
      `${page_file}: drawn in ${((Date.now() - started) / 1000).toFixed(1)} s by Chromium ${version} (WebGL: ${renderer}), ${width}x${height}, screenshot ${shot}`,
    );
  }
  if (status) console.log(console_lines.join('\n'));
} catch (e) {
  console.log(`${page_file}: ${e}`);
  status = 1;
} finally {
  await browser.close();
}
process.exit(status);
