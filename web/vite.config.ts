import { defineConfig } from 'vite';

// The page is served by `pneumid app` at / with its files under /assets/.
// The output folder is given on the command line: npm run build -- --outDir DIR
export default defineConfig({
  base: './',
  logLevel: 'warn',
  build: {
    outDir: process.env.PNEUMID_WEB_OUT ?? 'dist',
    emptyOutDir: true,
    assetsDir: 'assets',
    target: 'es2020',
    sourcemap: false,
    chunkSizeWarningLimit: 1000,
  },
});
