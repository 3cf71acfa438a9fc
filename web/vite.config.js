// The playground is a static site: `vite build` writes web/dist/ (index.html, the JS bundle,
// the worker, the wasm module and KaTeX's fonts), which any static server can serve.
import { defineConfig } from "vite";

export default defineConfig({
  base: "./",
  build: {
    outDir: "dist",
    emptyOutDir: true,
    target: "es2022",
    chunkSizeWarningLimit: 4096,
  },
  worker: { format: "es" },
  server: { fs: { allow: [".."] } },
});
