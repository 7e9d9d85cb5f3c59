// A bundle's files checked against its manifest.json, as `arwb play` checks them (src/bundle/open.cpp), by the page
// and by its service worker (sw.js): each file the manifest lists fetched from this origin, its size and SHA-256
// compared. A problem reads as the desktop's does: "scene/museum.lua: changed since export (SHA-256 differs)".
'use strict';
self.arwbVerify = (() => {
  const hex = (buffer) => [...new Uint8Array(buffer)].map((b) => b.toString(16).padStart(2, '0')).join('');
  const sha256 = async (buffer) => hex(await crypto.subtle.digest('SHA-256', buffer));

  // The manifest as served, or null when there is none (the page alone, not a bundle's).
  async function manifest(base) {
    const res = await fetch(new URL('manifest.json', base), { cache: 'no-store' });
    if (res.status === 404) return null;
    if (!res.ok) throw new Error(`manifest.json: the server answered ${res.status}`);
    const text = await res.text();
    let parsed;
    try {
      parsed = JSON.parse(text);
    } catch (e) {
      throw new Error(`manifest.json: not JSON (${e.message})`);
    }
    if (!parsed || !Array.isArray(parsed.files)) throw new Error('manifest.json: files: not a list');
    for (const [i, f] of parsed.files.entries())
      if (typeof f.path !== 'string' || f.path.includes('..') || f.path.startsWith('/') ||
          typeof f.size !== 'number' || !/^[0-9a-f]{64}$/.test(f.sha256))
        throw new Error(`manifest.json: files[${i}]: not a path, a size and a SHA-256`);
    return { text, parsed, digest: await sha256(new TextEncoder().encode(text)) };
  }

  // Every listed file fetched and checked: {files: Map(path -> ArrayBuffer) of the good ones, problems: [...]}.
  async function files(base, listed) {
    const good = new Map(), problems = [];
    for (const f of listed) {
      let res;
      try {
        res = await fetch(new URL(f.path, base), { cache: 'no-store' });
      } catch (e) {
        problems.push(`${f.path}: not fetched (${e.message})`);
        continue;
      }
      if (!res.ok) {
        problems.push(`${f.path}: missing (listed in the manifest; the server answered ${res.status})`);
        continue;
      }
      const body = await res.arrayBuffer();
      if (body.byteLength !== f.size)
        problems.push(`${f.path}: changed since export (${body.byteLength} bytes, the manifest says ${f.size})`);
      else if (await sha256(body) !== f.sha256) problems.push(`${f.path}: changed since export (SHA-256 differs)`);
      else good.set(f.path, body);
    }
    return { files: good, problems };
  }

  return { manifest, files, sha256 };
})();
