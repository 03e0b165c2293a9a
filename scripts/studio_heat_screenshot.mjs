// A screenshot of dpc studio with the heat map on (docs/images/studio-heat.png): dpc-demo
// --studio on the offline clock, headless chromium through puppeteer-core (the browser test's
// npm install, tests/studio/browser_test.sh), the "heat map" switch turned on, SECONDS of
// frames averaged, then the page saved.
//   node scripts/studio_heat_screenshot.mjs BUILD SCENE.json OUT.png [SECONDS]
import { spawn } from 'node:child_process';
import { createRequire } from 'node:module';
import path from 'node:path';

const [build, scene, out, seconds = '8'] = process.argv.slice(2);
if (!out) {
  console.error('usage: node scripts/studio_heat_screenshot.mjs BUILD SCENE.json OUT.png [SECONDS]');
  process.exit(2);
}
const puppeteer = createRequire(path.resolve(build, 'tests/studio-npm/package.json'))('puppeteer-core');
const child = spawn(path.resolve(build, 'apps/dpc-demo'),
                    [scene, '--studio', '--offline', path.resolve(build, 'heat-shot.wav'), '--duration', '0.5',
                     '--quiet', '--rays', '4096'], { stdio: ['ignore', 'pipe', 'inherit'] });
let printed = '';
const url = await new Promise((resolve, reject) => {
  child.on('exit', (code) => reject(new Error(`dpc-demo exited (${code})`)));
  child.stdout.on('data', (d) => {
    printed += d;
    const m = printed.match(/studio: (http\S+)/);
    if (m) resolve(m[1]);
  });
});
const browser = await puppeteer.launch({ executablePath: '/usr/bin/chromium', headless: true,
  args: ['--no-sandbox', '--enable-unsafe-swiftshader', '--use-angle=swiftshader', '--window-size=1280,800'] });
try {
  const page = await browser.newPage();
  await page.setViewport({ width: 1280, height: 800 });
  await page.goto(url, { waitUntil: 'load' });
  await page.waitForFunction(() => window.studio?.ready, { timeout: 120000 });
  await page.click('#heat');
  await new Promise((r) => setTimeout(r, Number(seconds) * 1000));
  await page.waitForFunction(() => window.studio.heat, { timeout: 60000 });
  await page.screenshot({ path: out });
  console.log(`wrote ${out}`);
} finally {
  await browser.close();
  child.removeAllListeners('exit');
  child.kill('SIGINT');
}
