// The phone player's service worker: the bundle kept on the phone, so that the page opens and plays offline. It
// is registered as sw.js?manifest=DIGEST (the SHA-256 of the manifest.json the page read), so a bundle exported
// again is a new worker: on install it fetches the manifest, which must have that digest, and every file the
// manifest lists, each checked (verify.js), and caches them only when all are good; otherwise the install fails and
// the page, which then checks the files itself, names the file. Requests for a cached file are answered from the
// cache; anything else goes to the network (this origin only: the page's Content-Security-Policy).
'use strict';
importScripts('web/verify.js');

const expected = new URL(location.href).searchParams.get('manifest') || '';
const cacheName = `arwb-bundle-${expected}`;
const base = new URL('./', location.href);
const types = { '.html': 'text/html', '.js': 'text/javascript', '.css': 'text/css', '.wasm': 'application/wasm',
                '.json': 'application/json', '.png': 'image/png', '.jpg': 'image/jpeg', '.jpeg': 'image/jpeg',
                '.mp4': 'video/mp4', '.webm': 'video/webm', '.txt': 'text/plain', '.pdf': 'application/pdf',
                '.lua': 'text/plain', '.xml': 'text/xml', '.woff2': 'font/woff2' };
const type = (path) => types[(path.match(/\.[^./]+$/) || [''])[0].toLowerCase()] || 'application/octet-stream';

self.addEventListener('install', (event) => {
  event.waitUntil((async () => {
    const m = await arwbVerify.manifest(base);
    if (!m) throw new Error('manifest.json: missing');
    if (m.digest !== expected) throw new Error('manifest.json: changed while the page was opening');
    const checked = await arwbVerify.files(base, m.parsed.files);
    if (checked.problems.length) throw new Error(checked.problems[0]);
    const cache = await caches.open(cacheName);
    const put = (path, body) => cache.put(new URL(path, base),
                                          new Response(body, { headers: { 'Content-Type': type(path) } }));
    await put('manifest.json', m.text);
    for (const [path, body] of checked.files) await put(path, body);
    // The page itself at its folder's address.
    if (checked.files.has('index.html')) await put('./', checked.files.get('index.html'));
    await self.skipWaiting();
  })());
});

self.addEventListener('activate', (event) => {
  event.waitUntil((async () => {
    for (const name of await caches.keys())
      if (name.startsWith('arwb-bundle-') && name !== cacheName) await caches.delete(name);
    await self.clients.claim();
  })());
});

self.addEventListener('fetch', (event) => {
  if (event.request.method !== 'GET') return;
  event.respondWith((async () => {
    const cache = await caches.open(cacheName);
    const url = new URL(event.request.url);
    url.search = '';
    // The manifest from the network when there is one (a bundle exported again shows as a new digest), else ours.
    if (url.pathname === new URL('manifest.json', base).pathname) {
      try {
        return await fetch(event.request, { cache: 'no-store' });
      } catch {
        return (await cache.match(url)) || Response.error();
      }
    }
    return (await cache.match(url)) || fetch(event.request);
  })());
});
