// Render TeX formulas with a MathJax 3 copy, offline: the check of scripts/check_offline_math.py.
// Usage: node scripts/render_math.js MATHJAX_DIR < formulas.json   ([[tex, display], ...] on stdin)
// Prints {"rendered": n, "bad": [[tex, message], ...]}.  The TeX input is the one the pages load
// (input/tex of tex-chtml.js) without "noundefined", so that an undefined macro, which the pages would
// show in red, is an error here.
const path = require('path').resolve(process.argv[2]);
global.MathJax = {
  loader: {require: require, paths: {mathjax: path}, load: ['input/tex', 'output/svg', 'adaptors/liteDOM']},
  tex: {packages: {'[-]': ['noundefined']}},
  svg: {fontCache: 'none'},
  startup: {typeset: false},
};
require(path + '/startup.js');
MathJax.startup.promise.then(() => {
  const formulas = JSON.parse(require('fs').readFileSync(0, 'utf8'));
  const bad = [];
  for (const [tex, display] of formulas) {
    const html = MathJax.startup.adaptor.outerHTML(MathJax.tex2svg(tex, {display}));
    const error = html.match(/data-mjx-error="([^"]*)"/);
    if (error || html.includes('merror')) bad.push([tex, error ? error[1] : 'merror']);
  }
  console.log(JSON.stringify({rendered: formulas.length, bad}));
}).catch((e) => { console.error(String(e)); process.exit(2); });
