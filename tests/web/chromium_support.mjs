// Debian's Chromium, headless, driven through its DevTools protocol over a pipe (--remote-debugging-pipe: messages
// are JSON separated by NUL bytes on file descriptors 3, to it, and 4, from it), so no port and no library.
//   const browser = await Chromium.launch({ args: ['--use-fake-device-for-media-stream', ...] });
//   const page = await browser.newPage(url);           // a tab, its Runtime and Network domains enabled
//   await page.evaluate('1 + 1');                      // 2 (awaits promises)
//   page.requests                                      // every URL the tab asked for
//   await browser.close();
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';

export class Chromium {
  static async launch({ args = [], binary = 'chromium' } = {}) {
    const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'arwb-chromium-'));
    const flags = ['--headless=new', '--no-sandbox', '--disable-gpu', '--no-first-run', '--no-default-browser-check',
                   '--disable-extensions', '--mute-audio', '--disable-background-networking',
                   '--disable-component-update', '--disable-dev-shm-usage', `--user-data-dir=${profile}`,
                   '--remote-debugging-pipe'];
    const child = spawn(binary, [...flags, ...args, 'about:blank'],
                        { stdio: ['ignore', 'ignore', 'pipe', 'pipe', 'pipe'], detached: true });
    const browser = new Chromium(child, profile);
    child.stderr.on('data', (d) => { browser.stderr += d; });
    await browser.send('Target.setDiscoverTargets', { discover: true });
    browser.version = (await browser.send('Browser.getVersion')).product;   // "HeadlessChrome/156..."
    return browser;
  }

  constructor(child, profile) {
    this.child = child;
    this.profile = profile;
    this.stderr = '';
    this.nextId = 1;
    this.pending = new Map();
    this.listeners = [];
    let buffered = '';
    child.stdio[4].on('data', (chunk) => {
      buffered += chunk.toString('utf8');
      let end;
      while ((end = buffered.indexOf('\0')) >= 0) {
        const message = JSON.parse(buffered.slice(0, end));
        buffered = buffered.slice(end + 1);
        this.dispatch(message);
      }
    });
    child.on('exit', (code) => {
      for (const { reject } of this.pending.values())
        reject(new Error(`chromium exited (${code}): ${this.stderr.slice(-2000)}`));
      this.pending.clear();
    });
  }

  dispatch(message) {
    if (message.id !== undefined && this.pending.has(message.id)) {
      const { resolve, reject, method } = this.pending.get(message.id);
      this.pending.delete(message.id);
      if (message.error) reject(new Error(`${method}: ${message.error.message}`));
      else resolve(message.result);
      return;
    }
    for (const listen of this.listeners) listen(message);
  }

  send(method, params = {}, sessionId = undefined) {
    const id = this.nextId++;
    const message = { id, method, params };
    if (sessionId) message.sessionId = sessionId;
    return new Promise((resolve, reject) => {
      this.pending.set(id, { resolve, reject, method });
      this.child.stdio[3].write(JSON.stringify(message) + '\0');
    });
  }

  async newPage(url, { width = 390, height = 844, mobile = true, scale = 1 } = {}) {
    const { targetId } = await this.send('Target.createTarget', { url: 'about:blank' });
    const { sessionId } = await this.send('Target.attachToTarget', { targetId, flatten: true });
    const page = new Page(this, sessionId);
    await page.send('Runtime.enable');
    await page.send('Network.enable');
    await page.send('Page.enable');
    await page.send('Emulation.setDeviceMetricsOverride', { width, height, deviceScaleFactor: scale, mobile });
    if (mobile) await page.send('Emulation.setTouchEmulationEnabled', { enabled: true, maxTouchPoints: 5 });
    await page.goto(url);
    return page;
  }

  async close() {
    try {
      await Promise.race([this.send('Browser.close'), new Promise((r) => setTimeout(r, 3000))]);
    } catch { /* already gone */ }
    // Debian's chromium is a script that starts the browser, which starts its helpers: all are in the process
    // group the launch made (detached), and all go.
    const exited = this.child.exitCode === null ? new Promise((resolve) => this.child.once('exit', resolve)) : null;
    try { process.kill(-this.child.pid, 'SIGKILL'); } catch { /* the group has gone */ }
    if (exited) await exited;
    // Its helpers may still be writing the profile for a moment.
    fs.rmSync(this.profile, { recursive: true, force: true, maxRetries: 10, retryDelay: 100 });
  }
}

class Page {
  constructor(browser, sessionId) {
    this.browser = browser;
    this.sessionId = sessionId;
    this.requests = [];
    this.console = [];
    this.exceptions = [];
    browser.listeners.push((m) => {
      if (m.sessionId !== sessionId) return;
      if (m.method === 'Network.requestWillBeSent') this.requests.push(m.params.request.url);
      if (m.method === 'Runtime.consoleAPICalled')
        this.console.push(m.params.args.map((a) => a.value ?? a.description ?? '').join(' '));
      if (m.method === 'Runtime.exceptionThrown')
        this.exceptions.push(m.params.exceptionDetails.exception?.description ?? m.params.exceptionDetails.text);
    });
  }

  send(method, params = {}) { return this.browser.send(method, params, this.sessionId); }

  async goto(url) {
    const loaded = new Promise((resolve) => {
      const listen = (m) => {
        if (m.sessionId === this.sessionId && m.method === 'Page.loadEventFired') {
          this.browser.listeners.splice(this.browser.listeners.indexOf(listen), 1);
          resolve();
        }
      };
      this.browser.listeners.push(listen);
    });
    await this.send('Page.navigate', { url });
    await loaded;
  }

  // The expression's value (awaited when a promise); a thrown error becomes this call's, with its text.
  async evaluate(expression) {
    const r = await this.send('Runtime.evaluate', { expression, awaitPromise: true, returnByValue: true });
    if (r.exceptionDetails)
      throw new Error(`in the page: ${r.exceptionDetails.exception?.description ?? r.exceptionDetails.text}`);
    return r.result.value;
  }

  // Polls `expression` until it is truthy, up to `seconds`; its last value.
  async waitFor(expression, seconds = 30) {
    const until = Date.now() + seconds * 1000;
    for (;;) {
      const v = await this.evaluate(expression);
      if (v) return v;
      if (Date.now() > until) throw new Error(`waited ${seconds} s for ${expression}`);
      await new Promise((r) => setTimeout(r, 100));
    }
  }

  // A finger's tap at (x, y) CSS pixels of the window: touch start and end, which the browser turns into a click.
  async tap(x, y) {
    await this.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: [{ x, y }] });
    await this.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] });
  }

  async screenshot(file) {
    const { data } = await this.send('Page.captureScreenshot', { format: 'png' });
    fs.writeFileSync(file, Buffer.from(data, 'base64'));
  }
}
