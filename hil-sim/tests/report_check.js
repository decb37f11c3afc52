// The layout check the report tests inject into a page (hil-sim/tests/report_browser.rs and
// scripts/report-screenshots): at the window width, nothing wider than the page, no table or
// <pre> that needs to scroll, no two SVG text boxes overlapping or outside their picture, no
// numeric table column without a unit (unless dimensionless), no e-notation outside plots.
// Writes its findings as JSON into <pre id="layout-check">.
(function () {
  const out = { width: innerWidth, page: document.documentElement.scrollWidth, overflow: [], overlaps: [], clipped: [], unitless: [], enotation: [] };
  if (document.documentElement.scrollWidth > innerWidth) out.overflow.push('page ' + document.documentElement.scrollWidth + ' px wide');
  document.querySelectorAll('table, pre').forEach((t, i) => {
    if (t.scrollWidth > t.clientWidth + 1) out.overflow.push(t.tagName.toLowerCase() + ' #' + i + ' needs ' + t.scrollWidth + ' px, has ' + t.clientWidth);
  });
  document.querySelectorAll('svg').forEach((svg, k) => {
    const sb = svg.getBoundingClientRect();
    const name = (svg.querySelector('text') || {}).textContent || ('svg ' + k);
    const boxes = [];
    svg.querySelectorAll('text').forEach(t => {
      const s = t.textContent.trim();
      if (!s) return;
      const r = t.getBoundingClientRect();
      if (r.width === 0) return;
      if (r.left < sb.left - 1 || r.right > sb.right + 1 || r.top < sb.top - 1 || r.bottom > sb.bottom + 1) out.clipped.push(name + ': "' + s + '"');
      boxes.push([s, r]);
    });
    for (let i = 0; i < boxes.length; i++) for (let j = i + 1; j < boxes.length; j++) {
      const a = boxes[i][1], b = boxes[j][1];
      const w = Math.min(a.right, b.right) - Math.max(a.left, b.left);
      const h = Math.min(a.bottom, b.bottom) - Math.max(a.top, b.top);
      if (w > 1 && h > 1) out.overlaps.push(name + ': "' + boxes[i][0] + '" / "' + boxes[j][0] + '"');
    }
  });
  const dimensionless = /R²|GOF|params|^#$|round|t-statistic|BIC|samples|^$/;
  document.querySelectorAll('table').forEach(t => {
    const heads = [...t.querySelectorAll('th')].map(h => h.textContent.trim());
    t.querySelectorAll('tbody tr').forEach(tr => [...tr.children].forEach((td, c) => {
      const h = heads[c] || '';
      if (/^[-+]?\d[\d.]*$/.test(td.textContent.trim()) && !h.includes('(') && !dimensionless.test(h)) out.unitless.push(h + ': ' + td.textContent.trim());
    }));
  });
  const walker = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
  for (let n = walker.nextNode(); n; n = walker.nextNode()) {
    const m = n.textContent.match(/\d[eE][-+]?\d+/);
    if (m && !(n.parentElement && n.parentElement.closest('svg'))) out.enotation.push(n.textContent.trim().slice(0, 80));
  }
  out.unitless = [...new Set(out.unitless)];
  const pre = document.createElement('pre');
  pre.id = 'layout-check';
  pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
})();
