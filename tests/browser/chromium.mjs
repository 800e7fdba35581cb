// What the browser tests share: Debian's Chromium, headless, drawing with
// software GL (SwiftShader) and fetching nothing of its own from the
// network; and a page's console and errors gathered as problems.
let chromium;
try {
  ({ chromium } = await import('playwright-core'));
} catch {
  console.error('playwright-core is not installed: run scripts/setup.sh (npm ci in tests/browser)');
  process.exit(1);
}

export function launchChromium() {
  return chromium.launch({
    executablePath: '/usr/bin/chromium',
    headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
      '--disable-background-networking', '--disable-component-update', '--disable-sync', '--no-first-run'],
  });
}

// Every console error and warning of `page`, and every error it throws,
// pushed to `problems` with the page's address, but for the messages `expected(type, text, url)`
// accepts (a test's own doing, not the page's).
export function watchConsole(page, problems, expected = () => false) {
  page.on('console', (m) => {
    if ((m.type() === 'error' || m.type() === 'warning') && !expected(m.type(), m.text(), page.url()))
      problems.push(`${m.type()}: ${m.text()} (${page.url()})`);
  });
  page.on('pageerror', (e) => problems.push(`pageerror: ${e.message} (${page.url()})`));
}
