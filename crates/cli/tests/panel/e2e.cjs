// The panel end to end in headless Chromium (driven by playwright-core), against the real
// `tezgah serve` the Rust test started: load a program, start it, see the highlighted line
// advance and the DRO change, hold and resume, jog, INC, MDI, zero-set, a second browser
// taking control; screenshots into OUT.
//
// node e2e.cjs PANEL_URL OUT_DIR   (env PLAYWRIGHT_CORE: the package's folder; CHROMIUM)

const { chromium } = require(process.env.PLAYWRIGHT_CORE);
const fs = require('fs');
const path = require('path');

const [url, out] = process.argv.slice(2);
const PROGRAM = [
  'G21 G90 G17',
  'G1 X10 Y5 F1500',
  'G1 X60 Y5 F600',
  'G2 X80 Y25 I0 J20',
  'G0 Z5',
  'M2',
].join('\n');

function check(cond, what) {
  if (!cond) throw new Error(`check failed: ${what}`);
  console.log(`ok: ${what}`);
}

const num = (page, id) => page.$eval(`#${id}`, (e) => Number(e.textContent));

async function main() {
  fs.mkdirSync(out, { recursive: true });
  const profile = fs.mkdtempSync(path.join(require('os').tmpdir(), 'tezgah-chromium-'));
  const browser = await chromium.launchPersistentContext(profile, {
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    headless: true,
    viewport: { width: 1280, height: 800 },
    args: ['--no-sandbox', '--disable-background-networking', '--disable-component-update',
      '--no-first-run', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
  });
  const errors = [];
  try {
    const page = browser.pages()[0] || await browser.newPage();
    page.on('pageerror', (e) => errors.push(`page error: ${e.message}`));
    page.on('console', (m) => { if (m.type() === 'error') errors.push(`console: ${m.text()}`); });
    await page.goto(url);
    await page.waitForFunction(() => window.tezgah && window.tezgah.status && window.tezgah.inControl);
    check(await page.$eval('#control-text', (e) => e.textContent.startsWith('in control')), 'the first page is in control');
    check(await page.$eval('#machine-name', (e) => e.textContent) === 'mill3', 'machine name shown');
    const late = await page.$eval('#late', (e) => e.textContent);
    check(/^\d+ µs/.test(late), `real-time lateness shown (${late})`);

    // Program: open from disk (a file chooser), then edit, load, preview.
    await page.setInputFiles('#file', { name: 'square.ngc', mimeType: 'text/plain',
      buffer: Buffer.from('G21 G90\nG1 X5 F600\nM2\n') });
    await page.waitForFunction(() => document.getElementById('program-name').textContent === 'square.ngc');
    check(await page.$$eval('#code .ln', (l) => l.length) === 4, 'a file opened from disk is shown');
    await page.click('#edit');
    await page.fill('#editor', PROGRAM);
    await page.click('#edit');
    await page.click('#load');
    await page.waitForFunction(() => window.tezgah.pieces.length > 0);
    const kinds = await page.evaluate(() => window.tezgah.pieces.map((p) => p.kind));
    check(['line', 'arc', 'rapid'].every((k) => kinds.includes(k)), `preview kinds ${kinds}`);
    check(await page.$$eval('#code .ln', (l) => l.length) === 6, 'six program lines shown');
    // The preview is drawn: many pixels differ from the background.
    await page.waitForTimeout(300);
    const lit = await page.evaluate(() => {
      const c = document.getElementById('view');
      const g = document.createElement('canvas');
      g.width = c.width; g.height = c.height;
      const x = g.getContext('2d');
      x.drawImage(c, 0, 0);
      const d = x.getImageData(0, 0, g.width, g.height).data;
      let n = 0;
      for (let i = 0; i < d.length; i += 4) if (Math.abs(d[i] - 16) + Math.abs(d[i + 1] - 19) + Math.abs(d[i + 2] - 22) > 60) n++;
      return n;
    });
    check(lit > 500, `the preview canvas is not blank (${lit} lit pixels)`);
    await page.screenshot({ path: path.join(out, 'panel-loaded.png') });

    // Run: the highlighted line advances, the DRO changes.
    await page.click('#cycle-start');
    await page.waitForSelector('#code .ln.current[data-line="2"]', { timeout: 10000 });
    check(true, 'line 2 highlighted');
    await page.waitForSelector('#code .ln.current[data-line="3"]', { timeout: 10000 });
    check(true, 'line 3 highlighted');
    await page.waitForFunction(() => Number(document.getElementById('m-X').textContent) > 20);
    const x1 = await num(page, 'm-X');
    check(x1 > 20 && x1 < 60, `DRO X moving on line 3 (${x1})`);
    const togo = await num(page, 'g-X');
    check(togo > 0 && Math.abs(x1 + togo - 60) < 1.5, `distance to go X ${togo} (to 60)`);

    // Feed override from the slider.
    await page.$eval('#feed-override', (e) => { e.value = 150; e.dispatchEvent(new Event('input')); });
    await page.waitForFunction(() => window.tezgah.status.feed_override_percent === 150);
    await page.$eval('#feed-override', (e) => { e.value = 100; e.dispatchEvent(new Event('input')); });
    await page.waitForFunction(() => window.tezgah.status.feed_override_percent === 100);
    check(true, 'feed override slider 150 % then 100 %');

    // Hold and resume.
    await page.click('#feed-hold');
    await page.waitForFunction(() => document.getElementById('state').textContent === 'held');
    const held = await num(page, 'm-X');
    await page.waitForTimeout(400);
    check(await num(page, 'm-X') === held, `held still at X ${held}`);
    await page.screenshot({ path: path.join(out, 'panel-held.png') });
    await page.click('#resume');
    await page.waitForFunction((h) => Number(document.getElementById('m-X').textContent) > h + 1, held);
    check(true, 'resumed');
    await page.waitForSelector('#code .ln.current[data-line="4"]', { timeout: 15000 });
    await page.waitForFunction(() => document.getElementById('state').textContent === 'idle', null, { timeout: 20000 });
    check(await page.$eval('#m-X', (e) => e.textContent) === '80.000', 'program ended at X 80');
    check(await page.$eval('#m-Y', (e) => e.textContent) === '25.000', 'program ended at Y 25');
    check(await page.$eval('#m-Z', (e) => e.textContent) === '5.000', 'program ended at Z 5');
    await page.waitForFunction(() => document.querySelectorAll('#plots canvas').length === 10);
    check(true, 'ten plots after the run (feed, 3 joints × v a j)');

    // JOG: X+ held for a while moves X up, then stops.
    const jog = await page.$('#jog-0-plus');
    const box = await jog.boundingBox();
    await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
    await page.mouse.down();
    await page.waitForTimeout(500);
    await page.mouse.up();
    await page.waitForFunction(() => document.getElementById('state').textContent === 'idle'
      && document.getElementById('mode').textContent === 'jog');
    const xj = await num(page, 'm-X');
    check(xj > 81 && xj < 100, `jogged X to ${xj}`);
    // Keyboard: Page Up jogs Z up.
    const z0 = await num(page, 'm-Z');
    await page.click('#view');
    await page.keyboard.down('PageUp');
    await page.waitForTimeout(300);
    await page.keyboard.up('PageUp');
    await page.waitForFunction(() => document.getElementById('state').textContent === 'idle');
    const z1 = await num(page, 'm-Z');
    check(z1 > z0 + 0.5, `keyboard jog Z ${z0} → ${z1}`);

    // INC: one step of 0.1 in Y.
    await page.check('#inc-mode');
    await page.check('input[name=inc][value="0.1"]');
    await page.click('#jog-1-plus');
    await page.waitForFunction(() => document.getElementById('m-Y').textContent === '25.100');
    check(true, 'INC Y by 0.1 to 25.100');
    await page.uncheck('#inc-mode');

    // MDI.
    await page.fill('#mdi', 'G1 X50 Y20 Z0 F3000');
    await page.press('#mdi', 'Enter');
    await page.waitForFunction(() => document.getElementById('m-X').textContent === '50.000'
      && document.getElementById('m-Y').textContent === '20.000' && document.getElementById('state').textContent === 'idle');
    check(await page.$eval('#mdi-history li', (e) => e.textContent) === 'G1 X50 Y20 Z0 F3000', 'MDI in the history');

    // Zero-set X and Y (G10 L20): work 0 here, machine unchanged, the offset shown.
    await page.click('#zero-X');
    await page.waitForFunction(() => document.getElementById('w-X').textContent === '0.000');
    await page.click('#zero-Y');
    await page.waitForFunction(() => document.getElementById('w-Y').textContent === '0.000');
    check(await page.$eval('#m-X', (e) => e.textContent) === '50.000', 'machine X unchanged by the zero-set');
    const offsets = await page.$eval('#offsets', (e) => e.textContent);
    check(offsets.startsWith('G54 offset 50.000 20.000 0.000'), `offsets: ${offsets}`);
    // A move in work coordinates lands at machine = work + offset.
    await page.fill('#mdi', 'G1 X5 Y5 F3000');
    await page.press('#mdi', 'Enter');
    await page.waitForFunction(() => document.getElementById('m-X').textContent === '55.000'
      && document.getElementById('w-X').textContent === '5.000' && document.getElementById('state').textContent === 'idle');
    check(true, 'MDI X5 in the zeroed frame is machine X 55');
    await page.screenshot({ path: path.join(out, 'panel-after.png'), fullPage: true });
    await page.locator('#plots-area').screenshot({ path: path.join(out, 'panel-plots.png') });

    // A second browser page watches; taking control is announced to both.
    const other = await browser.newPage();
    await other.goto(url);
    await other.waitForFunction(() => window.tezgah && window.tezgah.status);
    check(await other.$eval('#take-control', (e) => !e.hidden), 'the second page offers Take control');
    check(await other.$eval('#cycle-start', (e) => e.disabled), 'the second page cannot start a cycle');
    await other.click('#take-control');
    await other.waitForFunction(() => window.tezgah.inControl);
    await page.waitForFunction(() => !window.tezgah.inControl);
    check(await page.$eval('#control-text', (e) => e.textContent.startsWith('watching')), 'the first page now watches');
    await page.screenshot({ path: path.join(out, 'panel-watching.png') });

    // Errors at their line.
    await other.click('#edit');
    await other.fill('#editor', 'G21 G90\nG1 X10 F100\nG2 X5 Y5 R0.1\nM2');
    await other.click('#edit');
    await other.click('#load');
    await other.waitForSelector('#code .ln.bad[data-line="3"]');
    check(true, 'a load error marked at line 3');
    await other.close();
    // A tablet (portrait): one column, nothing wider than the screen.
    await page.setViewportSize({ width: 768, height: 1024 });
    await page.evaluate(() => window.scrollTo(0, 0));
    await page.waitForTimeout(200);
    const wide = await page.evaluate(() => document.documentElement.scrollWidth);
    check(wide <= 768, `fits a 768 px wide tablet (${wide} px)`);
    await page.screenshot({ path: path.join(out, 'panel-tablet.png') });
    check(errors.length === 0, `no page errors ${errors.join('; ')}`);
  } finally {
    await browser.close();
    fs.rmSync(profile, { recursive: true, force: true });
  }
}

main().then(() => process.exit(0), (e) => { console.error(e); process.exit(1); });
