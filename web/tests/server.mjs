// A static server for web/dist on 127.0.0.1 (an ephemeral port), for the browser tests and
// the benchmark: the files as a static host would serve them, gzip when the client asks
// (as any production host does), and the byte counts of what it sent.
import http from "node:http";
import fs from "node:fs";
import path from "node:path";
import zlib from "node:zlib";

const TYPES = {
  ".html": "text/html; charset=utf-8",
  ".js": "text/javascript",
  ".mjs": "text/javascript",
  ".css": "text/css",
  ".wasm": "application/wasm",
  ".json": "application/json",
  ".woff2": "font/woff2",
  ".woff": "font/woff",
  ".ttf": "font/ttf",
  ".svg": "image/svg+xml",
  ".png": "image/png",
};

export async function serve(root) {
  const sent = { raw: 0, gzip: 0, files: [] };
  const server = http.createServer((req, res) => {
    const url = new URL(req.url, "http://localhost");
    let file = path.join(root, decodeURIComponent(url.pathname));
    if (!file.startsWith(root)) {
      res.writeHead(403).end();
      return;
    }
    if (fs.existsSync(file) && fs.statSync(file).isDirectory()) file = path.join(file, "index.html");
    if (!fs.existsSync(file)) {
      res.writeHead(404).end("not found");
      return;
    }
    const body = fs.readFileSync(file);
    const type = TYPES[path.extname(file)] ?? "application/octet-stream";
    const gzip = /\bgzip\b/.test(req.headers["accept-encoding"] ?? "") && !type.startsWith("image/") && !type.startsWith("font/woff");
    const out = gzip ? zlib.gzipSync(body, { level: 9 }) : body;
    sent.raw += body.length;
    sent.gzip += out.length;
    sent.files.push({ path: url.pathname, bytes: out.length });
    res.writeHead(200, { "content-type": type, "content-length": out.length, ...(gzip ? { "content-encoding": "gzip" } : {}), "cache-control": "no-store" });
    res.end(out);
  });
  await new Promise((resolve) => server.listen(0, "127.0.0.1", resolve));
  const { port } = server.address();
  return { url: `http://127.0.0.1:${port}/`, sent, close: () => new Promise((r) => server.close(r)) };
}
