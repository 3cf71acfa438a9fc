// Headless Chromium (Debian's /usr/bin/chromium, or $CHROMIUM) driven by playwright-core:
// no browser is downloaded. Playwright gives each launch a fresh temporary profile (its own
// --user-data-dir); no background network, no component updates.
import { chromium } from "playwright-core";
import fs from "node:fs";

export async function launch() {
  const executablePath = process.env.CHROMIUM ?? "/usr/bin/chromium";
  if (!fs.existsSync(executablePath)) throw new Error(`no Chromium at ${executablePath} (apt-get install chromium, or set CHROMIUM)`);
  const browser = await chromium.launch({
    executablePath,
    headless: true,
    args: ["--no-sandbox", "--disable-background-networking", "--disable-component-update", "--disable-dev-shm-usage"],
  });
  return {
    browser,
    close: async () => {
      await browser.close();
    },
  };
}

/** Opens the playground at `hash`, waits until the engine is ready and the model loaded. */
export async function open(browser, base, hash = "") {
  const page = await browser.newPage({ viewport: { width: 1400, height: 1000 } });
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  await page.goto(`${base}${hash}`);
  await page.waitForSelector("body[data-ready='true'][data-loaded='true']", { timeout: 60000 });
  return { page, errors };
}

/** Clicks a command's button and waits for it to finish; returns the engine's answer. */
export async function command(page, cmd, timeout = 300000) {
  await page.evaluate(() => {
    window.pdynLast = null;
    delete document.body.dataset.lastCommand;
  });
  await page.click(`#${cmd}`);
  await page.waitForFunction(() => !document.body.dataset.busy && (window.pdynLast || document.querySelector("#error:not([hidden])")), null, { timeout });
  return page.evaluate(() => window.pdynLast);
}
