// Screenshots of each view of the playground for docs/web/ (looked at before they are kept):
//   scripts/build-web.sh && node web/scripts/screenshots.mjs
import path from "node:path";
import { serve } from "../tests/server.mjs";
import { launch, open, command } from "../tests/browser.mjs";

const root = path.resolve(new URL("../..", import.meta.url).pathname);
const dir = path.join(root, "docs", "web");
const server = await serve(path.join(root, "web", "dist"));
const { browser, close } = await launch();
const shot = (page, name) => page.screenshot({ path: path.join(dir, `${name}.png`) });
try {
  let { page } = await open(browser, server.url, "#example=examples/satellite_ode45.toml");
  await command(page, "run");
  await shot(page, "plots");
  await page.click("#tab-animation");
  await page.evaluate(() => {
    const s = document.getElementById("frame");
    s.value = String(Math.floor(Number(s.max) * 0.7));
    s.dispatchEvent(new Event("input"));
  });
  await shot(page, "animation");
  await page.click("#tab-text");
  await shot(page, "text");
  await command(page, "derive");
  await shot(page, "equations");
  await page.close();

  ({ page } = await open(browser, server.url, "#example=examples/nbody/outer_solar_system.toml"));
  await command(page, "run");
  await page.click("#tab-animation");
  await shot(page, "nbody");
  await page.close();

  ({ page } = await open(browser, server.url, "#example=examples/md/lj_liquid.toml"));
  await command(page, "run");
  await page.click("#tab-animation");
  await shot(page, "md");
  await page.close();

  ({ page } = await open(browser, server.url, "#example=examples/kin/polar_example.sh"));
  await command(page, "run");
  await shot(page, "kin");
  await page.close();

  ({ page } = await open(browser, server.url, "#example=examples/satellite.toml"));
  await page.evaluate(() => (window.pdynEditor.text = window.pdynEditor.text.replace('strength = "GM*m"', 'strength = "GM*m*"')));
  await command(page, "run");
  await shot(page, "error");
  await page.close();
} finally {
  await close();
  await server.close();
}
console.log(`screenshots in ${dir}`);
