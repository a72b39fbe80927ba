// Builds the page into the Python package (git-ignored), served by cadkg serve under /static/dist/.
import { fileURLToPath } from "node:url";
import { defineConfig } from "vite";

export default defineConfig({
  root: fileURLToPath(new URL(".", import.meta.url)),
  base: "/static/dist/",
  build: {
    outDir: fileURLToPath(new URL("../src/cadkg/server/static/dist", import.meta.url)),
    emptyOutDir: true,
    // Everything the page loads is a file of its own: the CSP allows no inline code or data.
    assetsInlineLimit: 0,
    modulePreload: { polyfill: false },
    chunkSizeWarningLimit: 800,
    reportCompressedSize: false,
  },
});
