// Drives a page of `prru view` in headless chromium (playwright-core from
// web/node_modules, the browser given by $PRRU_CHROMIUM) for
// tests/test_cli_view.sh, and writes what it saw as JSON:
//   node view_browser.js PAGE.html OUT.json [SCREENSHOT.png]
// OUT.json: console and page errors, the frame count, the non-background
// pixels of the 3-D canvas at the first frame, the pixels that changed when
// the slider was moved to the last frame (with the keyboard, as a user
// would), whether Play advanced the frame, and for frames 0, the middle and
// the last: what the page holds (prruView.poseAt) and how the bodies are
// placed as drawn (prruView.drawn, three.js matrices), all as the page's
// JavaScript numbers.
'use strict';
const { chromium } = require('playwright-core');
const fs = require('fs');
const path = require('path');

async function main() {
  const [page_file, out_file, shot] = process.argv.slice(2);
  const browser = await chromium.launch({
    executablePath: process.env.PRRU_CHROMIUM || '/usr/bin/chromium',
    headless: true,
    // root in a container has no user namespace sandbox; WebGL through
    // SwiftShader (no GPU here).
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
  const r = { errors: [], warnings: [] };
  try {
    const page = await browser.newPage({ viewport: { width: 1100, height: 700 } });
    page.on('console', (m) => {
      if (m.type() === 'error') r.errors.push(`console: ${m.text()}`);
      if (m.type() === 'warning') r.warnings.push(m.text());
    });
    page.on('pageerror', (e) => r.errors.push(`page: ${e.message}`));
    // Offline by construction: a request for anything but the page itself
    // and the blob: of three.js is an error.
    const self = new URL('file://' + path.resolve(page_file)).href;
    page.on('request', (q) => {
      if (q.url() !== self && !q.url().startsWith('blob:')) r.errors.push(`request: ${q.url()}`);
    });
    await page.goto('file://' + path.resolve(page_file));
    await page.waitForFunction(() => window.prruView && window.prruView.ready, null, { timeout: 30000 });
    r.nframes = await page.evaluate(() => window.prruView.nframes);
    r.title = await page.title();
    r.info = await page.evaluate(() => document.getElementById('info').textContent);
    r.pwned = await page.evaluate(() => window.pwned);
    r.map_shown = await page.evaluate(() => !document.getElementById('map-panel').hidden);
    // The canvas's pixels, kept in the page (shipping megabytes of RGBA
    // to node is slow): snap(name) stores them, the counts come back.
    await page.evaluate(() => {
      const shots = {};
      window.__test = {
        snap(name) {
          const c = document.getElementById('view3d'), t = document.createElement('canvas');
          t.width = c.width;
          t.height = c.height;
          const g = t.getContext('2d');
          g.drawImage(c, 0, 0);
          shots[name] = g.getImageData(0, 0, t.width, t.height).data;
          return shots[name].length / 4;
        },
        nonWhite(name) {
          const a = shots[name];
          let n = 0;
          for (let i = 0; i < a.length; i += 4) if (a[i] < 250 || a[i + 1] < 250 || a[i + 2] < 250) n++;
          return n;
        },
        diff(x, y) {
          const a = shots[x], b = shots[y];
          let n = 0;
          for (let i = 0; i < a.length; i += 4) if (a[i] !== b[i] || a[i + 1] !== b[i + 1] || a[i + 2] !== b[i + 2]) n++;
          return n;
        },
      };
    });
    r.pixels = await page.evaluate(() => window.__test.snap('first'));
    r.non_background = await page.evaluate(() => window.__test.nonWhite('first'));
    if (shot) await page.screenshot({ path: shot });
    // Scrub with the keyboard: the slider to its end.
    await page.focus('#scrub');
    await page.keyboard.press('End');
    r.frame_after_scrub = await page.evaluate(() => window.prruView.frame());
    await page.evaluate(() => window.__test.snap('last'));
    r.changed = await page.evaluate(() => window.__test.diff('first', 'last'));
    // Play from the start for a while.
    await page.keyboard.press('Home');
    await page.click('#play');
    r.frame_after_play = 0;
    try {
      await page.waitForFunction(() => window.prruView.frame() > 0, null, { timeout: 10000 });
      r.frame_after_play = await page.evaluate(() => window.prruView.frame());
    } catch (e) { /* stays 0: reported by the test */ }
    await page.click('#play');
    // The arrows toggle, when the run has reactions.
    r.arrows = await page.evaluate(() => !document.getElementById('arrows-label').hidden);
    if (r.arrows) {
      await page.check('#arrows');
      await page.evaluate(() => window.__test.snap('on'));
      await page.uncheck('#arrows');
      await page.evaluate(() => window.__test.snap('off'));
      r.arrow_pixels = await page.evaluate(() => window.__test.diff('on', 'off'));
    }
    r.poses = [];
    for (const k of [0, Math.floor(r.nframes / 2), r.nframes - 1]) {
      await page.evaluate((k) => window.prruView.setFrame(k), k);
      r.poses.push(await page.evaluate((k) => {
        const v = window.prruView, d = v.poseAt(k);
        return { k, row: d.row, t: d.t, q: Array.from(d.q), R: Array.from(d.R), p: Array.from(d.p),
          is_array: Array.isArray(d.R) && Array.isArray(d.p), drawn: v.drawn() };
      }, k));
    }
  } catch (e) {
    r.errors.push(`driver: ${e.message}`);
  } finally {
    await browser.close();
  }
  fs.writeFileSync(out_file, JSON.stringify(r));
}

main().catch((e) => { console.error(e); process.exit(1); });
