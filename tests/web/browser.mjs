// Drives Debian's chromium (through playwright-core, no browser download) against a running
// `pointrast serve` for tests/web/browser_test.cpp, which starts the server, picks the scenario and checks
// the JSON this prints on its last line. The network here is closed: chromium is started with everything
// that would reach out turned off, and a fresh profile in a temporary folder.
//
//   node browser.mjs SCENARIO URL OUTDIR [JSON-ARGS]
import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';

const [scenario, url, outdir, argsText] = process.argv.slice(2);
const args = argsText ? JSON.parse(argsText) : {};
const TIMEOUT = 120000;

// Chromium's own output (its stderr and playwright's record of the process, which playwright writes to
// this process's stderr under DEBUG=pw:browser) is kept, not printed, to say why should the browser go
// away in the middle of a scenario.
const browserLog = [];
const keep = (text) => {
  for (const line of text.split('\n')) // the debug lines carry their time; chromium's D-Bus noise is left out
    if (line.trim() && !line.includes('ERROR:dbus/')) browserLog.push(line);
  browserLog.splice(0, Math.max(0, browserLog.length - 80));
};
process.env.DEBUG = [process.env.DEBUG, 'pw:browser'].filter(Boolean).join(',');
const stderrWrite = process.stderr.write.bind(process.stderr);
process.stderr.write = (chunk, ...rest) => {
  if (!String(chunk).includes('pw:browser')) return stderrWrite(chunk, ...rest); // node's own errors
  keep(String(chunk));
  const done = rest.find((r) => typeof r === 'function');
  if (done) done();
  return true;
};
const { chromium } = await import('playwright-core');

async function launch(viewport) {
  const profile = mkdtempSync(join(tmpdir(), 'pointrast-chromium-'));
  const flags = ['--headless', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
                 '--disable-component-update', '--disable-sync'];
  if (process.getuid && process.getuid() === 0) flags.push('--no-sandbox');
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: process.env.POINTRAST_CHROMIUM || '/usr/bin/chromium',
    headless: true, args: flags, viewport, deviceScaleFactor: 1, timeout: TIMEOUT,
  });
  context.on('close', () => keep(`${new Date().toISOString()} the browser context closed`));
  context.setDefaultTimeout(TIMEOUT);
  return { context, close: async () => { await context.close(); rmSync(profile, { recursive: true, force: true }); } };
}

// Waits until the page has drawn a full frame (the one at rest) whose input sequence number is at least
// `seq` and whose size is `size` when given, and the state that came with it.
async function waitFull(page, seq = 0, size = null) {
  await page.waitForFunction(([seq, size]) => {
    const p = window.pointrast;
    const f = p && p.lastFrame;
    return f && f.full && f.seq >= seq && p.state && p.state.frame === f.frame &&
           (!size || (f.viewWidth === size[0] && f.viewHeight === size[1]));
  }, [seq, size], { timeout: TIMEOUT, polling: 50 });
  return page.evaluate(() => ({ state: window.pointrast.state, frame: window.pointrast.lastFrame, frames: window.pointrast.frames }));
}

async function open(context, target) {
  const page = await context.newPage();
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  page.on('crash', () => errors.push('the page crashed'));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  const response = await page.goto(target);
  return { page, errors, status: response ? response.status() : 0 };
}

async function canvasPng(page, file) {
  const data = await page.evaluate(() => document.getElementById('view').toDataURL('image/png'));
  writeFileSync(file, Buffer.from(data.split(',')[1], 'base64'));
}

async function drag(page, from, to, button) {
  await page.mouse.move(from[0], from[1]);
  await page.mouse.down({ button });
  await page.mouse.move(to[0], to[1], { steps: 8 });
  await page.mouse.up({ button });
}

async function settle(page) {
  // After the release the session rests: the next full frame shows the final camera.
  await page.waitForTimeout(100);
  const seq = await page.evaluate(() => window.pointrast.sentSeq);
  return waitFull(page, seq);
}

const scenarios = {
  // The first frame at rest, as a PNG of the canvas, with the state it came with.
  async frame(context) {
    const { page, errors, status } = await open(context, url);
    const shown = await waitFull(page);
    await canvasPng(page, join(outdir, 'canvas.png'));
    const canvas = await page.evaluate(() => [document.getElementById('view').width, document.getElementById('view').height]);
    return { status, errors, canvas, ...shown };
  },
  // A drag on the canvas: the cameras before and after, for the test to compare with the session core.
  async drag(context) {
    const { page, errors } = await open(context, url);
    const before = await waitFull(page);
    await drag(page, args.from, args.to, args.button || 'left');
    const after = await settle(page);
    return { errors, before, after };
  },
  // The window resized: frames follow at the new size.
  async resize(context) {
    const { page, errors } = await open(context, url);
    const before = await waitFull(page);
    await page.setViewportSize({ width: args.width, height: args.height });
    const after = await waitFull(page, 0, [args.width, args.height]);
    const canvas = await page.evaluate(() => [document.getElementById('view').width, document.getElementById('view').height]);
    return { errors, before, after, canvas };
  },
  // Two tabs: a drag in the first moves only its camera.
  async two(context) {
    const a = await open(context, url), b = await open(context, url);
    const a0 = await waitFull(a.page), b0 = await waitFull(b.page);
    await a.page.bringToFront();
    await drag(a.page, args.from, args.to, 'left');
    const a1 = await settle(a.page);
    await b.page.waitForTimeout(500);
    const b1 = await b.page.evaluate(() => ({ state: window.pointrast.state, frames: window.pointrast.frames }));
    return { errors: [...a.errors, ...b.errors], a0, b0, a1, b1 };
  },
  // Without the token, with a wrong one and with the right one: the page, and a WebSocket opened by script.
  async token(context) {
    const base = new URL(url);
    base.search = '';
    const results = {};
    for (const [name, target] of [['none', base.href], ['wrong', base.href + '?token=wrong' + args.token.slice(5)], ['right', url]]) {
      const page = await context.newPage();
      const response = await page.goto(target);
      results[name] = { status: response ? response.status() : 0 };
      if (name === 'right') results[name].shown = await waitFull(page);
      await page.close();
    }
    // The sockets are opened by script on the server's own origin (chromium keeps pages of other origins,
    // about:blank included, from reaching local addresses), from its refusal page, without the cookie that
    // the right token's page set.
    await context.clearCookies();
    const blank = await context.newPage();
    await blank.goto(base.href);
    const ws = base.href.replace('http:', 'ws:') + 'ws';
    for (const [name, target] of [['wsNone', ws], ['wsWrong', ws + '?token=wrong' + args.token.slice(5)], ['wsRight', ws + '?token=' + args.token]]) {
      results[name] = await blank.evaluate((target) => new Promise((resolve) => {
        const socket = new WebSocket(target);
        let opened = false;
        socket.onopen = () => { opened = true; socket.close(); };
        socket.onclose = () => resolve({ opened });
        setTimeout(() => resolve({ opened, timeout: true }), 10000);
      }), target);
    }
    return results;
  },
  // The panel's controls changed one after another (args.steps: {id, value} sets an input or select, {id,
  // check} a checkbox, then a "change" event as a user's edit fires): after each, the full frame drawn with
  // the settings that step asked for (the state's render options equal step.expect), as step-N.png.
  async settings(context) {
    const { page, errors } = await open(context, url);
    await waitFull(page);
    const shown = [];
    for (const [i, step] of args.steps.entries()) {
      if ('check' in step) await page.setChecked('#' + step.id, step.check);
      else await page.evaluate(([id, value]) => {
        const element = document.getElementById(id);
        element.value = String(value);
        element.dispatchEvent(new Event('change', { bubbles: true }));
      }, [step.id, step.value]);
      await page.waitForFunction((expect) => {
        const p = window.pointrast;
        return p.state && p.state.settings.options === expect && p.lastFrame && p.lastFrame.full &&
               p.lastFrame.seq >= p.sentSeq && p.state.frame === p.lastFrame.frame;
      }, step.expect, { timeout: TIMEOUT, polling: 50 });
      await canvasPng(page, join(outdir, `step-${i}.png`));
      shown.push(await page.evaluate(() => window.pointrast.state.settings.options));
    }
    if (args.file) await page.screenshot({ path: args.file });
    const refusals = await page.evaluate(() => window.pointrast.refusals);
    return { errors, shown, refusals };
  },
  // The pick and measure tools: args.steps, each {tool, pixel: [x, y]} (a pixel of the frame) clicked with that
  // tool chosen in the panel; after each click, the pick the page received, the text it shows and the
  // measurement list. args.ctrl: Ctrl+click with the tool left at "navigates". A step {tool, drag: [[x0, y0],
  // [x1, y1]]} presses at the first pixel and releases at the second instead: the page's "moved" answer and
  // the list that follows it.
  async tools(context) {
    const { page, errors } = await open(context, url);
    const shown = await waitFull(page);
    const results = [];
    for (const step of args.steps) {
      const tool = args.ctrl ? 'navigate' : step.tool;
      if (await page.inputValue('#tool') !== tool) await page.selectOption('#tool', tool); // a change finishes a measurement
      const [before, lists] = await page.evaluate(() => [window.pointrast.picks, window.pointrast.measurementUpdates || 0]);
      const client = (pixel) => page.evaluate(([x, y, w, h]) => {
        const r = document.getElementById('view').getBoundingClientRect();
        return [r.left + (x + 0.5) * r.width / w, r.top + (y + 0.5) * r.height / h];
      }, [...pixel, shown.frame.viewWidth, shown.frame.viewHeight]);
      if (step.drag) {
        const moves = await page.evaluate(() => window.pointrast.moves || 0);
        const [from, to] = [await client(step.drag[0]), await client(step.drag[1])];
        await page.mouse.move(from[0], from[1]);
        await page.mouse.down();
        await page.mouse.move(to[0], to[1], { steps: 4 });
        await page.mouse.up();
        await page.waitForFunction((n) => (window.pointrast.moves || 0) > n, moves, { timeout: TIMEOUT, polling: 50 });
        await page.waitForFunction((n) => (window.pointrast.measurementUpdates || 0) > n, lists, { timeout: TIMEOUT, polling: 50 });
        results.push(await page.evaluate(() => ({ moved: window.pointrast.moved, measurements: window.pointrast.measurements })));
        continue;
      }
      const at = await client(step.pixel);
      if (args.ctrl) await page.keyboard.down('Control');
      await page.mouse.click(at[0], at[1]);
      if (args.ctrl) await page.keyboard.up('Control');
      await page.waitForFunction((n) => window.pointrast.picks > n, before, { timeout: TIMEOUT, polling: 50 });
      // A measuring click: the list that follows the pick.
      if (!args.ctrl && step.tool !== 'pick')
        await page.waitForFunction((n) => (window.pointrast.measurementUpdates || 0) > n, lists, { timeout: TIMEOUT, polling: 50 });
      results.push(await page.evaluate(() => ({ pick: window.pointrast.picked, text: document.getElementById('picked').textContent,
        measurements: window.pointrast.measurements, listText: document.getElementById('measurements').textContent })));
    }
    let annotations = null;
    if (args.download) {
      const [download] = await Promise.all([page.waitForEvent('download'), page.click('#downloadMeasures')]);
      const file = join(outdir, 'annotations.json');
      await download.saveAs(file);
      annotations = file;
    }
    const after = await page.evaluate(() => ({ state: window.pointrast.state }));
    return { errors, shown, results, annotations, after };
  },
  // The Export button with args.box ("x0,y0,z0,x1,y1,z1" or ""), args.mode and args.classes in the panel:
  // the downloaded file as export.las, and what the page reported (points, or the error it showed).
  async export(context) {
    const { page, errors } = await open(context, url);
    await waitFull(page);
    await page.fill('#clipBox', args.box || '');
    if (args.mode) await page.selectOption('#clipMode', args.mode);
    await page.fill('#exportClasses', args.classes || '');
    let file = null;
    const downloaded = page.waitForEvent('download', { timeout: TIMEOUT }).then(async (download) => {
      file = join(outdir, 'export.las');
      await download.saveAs(file);
    }).catch(() => {});
    await page.click('#exportLas');
    await page.waitForFunction(() => window.pointrast.exported, null, { timeout: TIMEOUT, polling: 50 });
    const exported = await page.evaluate(() => window.pointrast.exported);
    if (!exported.error) await downloaded;
    const shown = await page.evaluate(() => document.getElementById('exportStatus').textContent);
    return { errors, exported, shown, file };
  },
  // The profile tool: args.pixels (pixels of the frame) clicked with "draws a profile line" chosen, args.width
  // typed into Width when given (else the page's default stays), args.size into Size. After the clicks, the
  // profile the page cut (its line, width, size and points), the picture it shows as profile.png, and for
  // each of args.downloads ("las", "csv") the file its button downloaded as profile-download.KIND.
  async profile(context) {
    const { page, errors } = await open(context, url);
    const shown = await waitFull(page);
    const defaultWidth = await page.inputValue('#profileWidth');
    if (args.width !== undefined) await page.fill('#profileWidth', String(args.width));
    if (args.size) await page.fill('#profileSize', args.size);
    await page.selectOption('#tool', 'profile');
    for (const pixel of args.pixels) {
      const cuts = await page.evaluate(() => window.pointrast.profileCuts);
      const picks = await page.evaluate(() => window.pointrast.picks);
      const at = await page.evaluate(([x, y, w, h]) => {
        const r = document.getElementById('view').getBoundingClientRect();
        return [r.left + (x + 0.5) * r.width / w, r.top + (y + 0.5) * r.height / h];
      }, [...pixel, shown.frame.viewWidth, shown.frame.viewHeight]);
      await page.mouse.click(at[0], at[1]);
      await page.waitForFunction((n) => window.pointrast.picks > n, picks, { timeout: TIMEOUT, polling: 50 });
      // From the second vertex on, every click cuts the profile again.
      if (pixel !== args.pixels[0])
        await page.waitForFunction((n) => window.pointrast.profileCuts > n, cuts, { timeout: TIMEOUT, polling: 50 });
    }
    const profile = await page.evaluate(() => window.pointrast.profile);
    const visible = await page.evaluate(() => !document.getElementById('profilePanel').hidden);
    const picture = await page.evaluate(async () => {
      const image = document.getElementById('profileImage');
      if (!window.pointrast.profileImage) return null;
      const bytes = new Uint8Array(await window.pointrast.profileImage.arrayBuffer());
      let text = '';
      for (const b of bytes) text += String.fromCharCode(b);
      return { base64: btoa(text), width: image.naturalWidth, height: image.naturalHeight };
    });
    let image = null;
    if (picture) {
      image = join(outdir, 'profile.png');
      writeFileSync(image, Buffer.from(picture.base64, 'base64'));
    }
    const downloads = {};
    for (const kind of (profile && profile.error ? [] : args.downloads || [])) {
      const [download] = await Promise.all([page.waitForEvent('download', { timeout: TIMEOUT }), page.click('#profile' + kind[0].toUpperCase() + kind.slice(1))]);
      const file = join(outdir, 'profile-download.' + kind);
      await download.saveAs(file);
      downloads[kind] = { file, ...(await page.evaluate(() => window.pointrast.profileDownload)) };
    }
    const status = await page.evaluate(() => document.getElementById('profileStatus').textContent);
    return { errors, shown, defaultWidth, profile, visible, image, imageSize: picture && [picture.width, picture.height], downloads, status };
  },
  // A picture of the page (panel and frame) for the README.
  async pageshot(context) {
    const { page, errors } = await open(context, url);
    await waitFull(page);
    // An octree: once the frame drew the whole selection.
    if (args.converged)
      await page.waitForFunction(() => {
        const p = window.pointrast;
        return p.state && p.state.stats.lod && p.state.stats.lod.converged && p.lastFrame &&
               p.lastFrame.full && p.state.frame === p.lastFrame.frame;
      }, null, { timeout: TIMEOUT, polling: 100 });
    await page.waitForTimeout(300);
    await page.screenshot({ path: join(outdir, args.file || 'page.png') });
    return { errors };
  },
};

const viewport = { width: args.viewportWidth || 640, height: args.viewportHeight || 480 };
let browser = null;
let result;
try {
  browser = await launch(viewport);
  result = await scenarios[scenario](browser.context);
} catch (error) {
  result = { failure: String(error && error.stack || error) + '\nchromium, last lines:\n' + browserLog.join('\n') };
}
if (browser) await browser.close().catch((error) => keep(`closing the browser: ${error}`));
console.log(JSON.stringify(result));
