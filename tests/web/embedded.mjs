// A notebook's output cell in chromium: a page on another origin (http://localhost:PORT, as Jupyter's)
// holds the HTML that pointrast.show() gives Jupyter (an iframe of the viewer on 127.0.0.1). Prints one JSON
// line: whether the framed viewer connected and drew a full frame, and the errors the pages reported.
//
//   node embedded.mjs 'HTML'
import { chromium } from 'playwright-core';
import { createServer } from 'node:http';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';

const html = process.argv[2];
const TIMEOUT = 60000;
const host = createServer((request, response) => {
  response.writeHead(200, { 'Content-Type': 'text/html; charset=utf-8' });
  response.end('<!doctype html><html><body><div class="output">' + html + '</div></body></html>');
});
await new Promise((resolve) => host.listen(0, 'localhost', resolve));

const profile = mkdtempSync(join(tmpdir(), 'pointrast-chromium-'));
const flags = ['--headless', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
               '--disable-component-update', '--disable-sync'];
if (process.getuid && process.getuid() === 0) flags.push('--no-sandbox');
const context = await chromium.launchPersistentContext(profile, {
  executablePath: process.env.POINTRAST_CHROMIUM || '/usr/bin/chromium',
  headless: true, args: flags, viewport: { width: 800, height: 700 }, timeout: TIMEOUT,
});
const result = { drawn: false, errors: [] };
try {
  const page = await context.newPage();
  page.on('console', (m) => { if (m.type() === 'error') result.errors.push(m.text()); });
  await page.goto(`http://localhost:${host.address().port}/`);
  const element = await page.waitForSelector('iframe', { timeout: TIMEOUT });
  const frame = await element.contentFrame();
  await frame.waitForFunction(() => {
    const p = window.pointrast;
    return p && p.lastFrame && p.lastFrame.full && p.frames > 0;
  }, null, { timeout: TIMEOUT, polling: 50 });
  result.drawn = true;
  result.frame = await frame.evaluate(() => ({ width: window.pointrast.lastFrame.width,
                                                height: window.pointrast.lastFrame.height,
                                                errors: window.pointrast.errors }));
} catch (e) {
  result.errors.push(String(e).split('\n')[0]);
} finally {
  await context.close();
  rmSync(profile, { recursive: true, force: true });
  host.close();
}
console.log(JSON.stringify(result));
