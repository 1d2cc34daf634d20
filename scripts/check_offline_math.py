"""Check that a built HTML site shows its equations without a network (issue 35).

The pages load MathJax from the site itself (``_static/mathjax``, vendored by the docs extra's
sphinx-mathjax-offline), not from a CDN.  This checks, for every page of ``docs/_build/html``:

1. no script, stylesheet, font, image or frame is loaded from another host (``http://``, ``https://`` or
   ``//``): the page works offline (links a reader follows, ``<a href>``, may point anywhere);
2. the MathJax script a page loads exists in the site, with the TeX input and the output it needs;
3. every formula of every page renders: the same MathJax files, run offline by node
   (``scripts/render_math.js``), typeset each formula's TeX; one that MathJax cannot parse (an unknown
   macro, a missing brace) fails the check.  A page's formulas are what Sphinx wrote between MathJax's
   delimiters ``\\(...\\)`` and ``\\[...\\]`` in elements of class ``math``, which MathJax's default
   configuration typesets.

``scripts/build_docs.sh`` runs it after every build.  Usage: python scripts/check_offline_math.py docs/_build/html
"""

from __future__ import annotations

import html
import json
import re
import shutil
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

RENDERER = Path(__file__).resolve().parent / "render_math.js"
REMOTE = re.compile(r"^(?:[a-z][a-z0-9+.-]*:)?//", re.I)
# The attributes that load something into the page (a reader's link, <a href>, loads nothing by itself).
LOADING = {"script": "src", "img": "src", "iframe": "src", "source": "src", "audio": "src", "video": "src",
           "embed": "src", "object": "data"}


class _Page(HTMLParser):
    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.remote: list[str] = []
        self.scripts: list[str] = []
        self.formulas: list[tuple[str, bool]] = []
        self._math: list[tuple[str, bool]] = []  # open math elements: (tag, display)
        self._text: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        values = dict(attrs)
        target = values.get(LOADING.get(tag, ""))
        if tag == "link" and set((values.get("rel") or "").split()) & {"stylesheet", "preload", "modulepreload", "icon"}:
            target = values.get("href")
        if target and REMOTE.match(target):
            self.remote.append(f"<{tag}> {target}")
        if tag == "script" and values.get("src"):
            self.scripts.append(values["src"])
        if "math" in (values.get("class") or "").split():
            self._math.append((tag, tag == "div"))
            self._text = []

    def handle_endtag(self, tag: str) -> None:
        if self._math and self._math[-1][0] == tag:
            _, display = self._math.pop()
            text = "".join(self._text).strip()
            for match in re.finditer(r"\\\((.*?)\\\)|\\\[(.*?)\\\]", text, re.S):
                inline, block = match.groups()
                self.formulas.append((inline if inline is not None else block, block is not None))

    def handle_data(self, data: str) -> None:
        if self._math:
            self._text.append(data)


def check(site: Path) -> tuple[list[str], int]:
    """(problems, formulas rendered) of the built site ``site``."""
    problems: list[str] = []
    formulas: list[tuple[str, bool]] = []
    where: list[str] = []
    mathjax: set[Path] = set()
    pages = sorted(site.rglob("*.html"))
    if not pages:
        return [f"{site}: no HTML pages (build the site first: scripts/build_docs.sh)"], 0
    for page in pages:
        parser = _Page()
        parser.feed(page.read_text(encoding="utf-8"))
        problems += [f"{page.relative_to(site)}: loads {item} from another host" for item in parser.remote]
        for src in parser.scripts:
            if "mathjax" in src.lower() and not REMOTE.match(src):
                mathjax.add((page.parent / src.split("?")[0]).resolve())
        formulas += parser.formulas
        where += [str(page.relative_to(site))] * len(parser.formulas)
    if formulas and not mathjax:
        problems.append("the pages hold formulas but load no MathJax script of their own")
    for script in sorted(mathjax):
        if not script.is_file():
            problems.append(f"the MathJax script {script} the pages load is not in the site")
        elif not (script.parent / "startup.js").is_file() or not (script.parent / "input" / "tex.js").is_file():
            problems.append(f"{script.parent} lacks MathJax's startup.js or input/tex.js")
    if problems or not formulas:
        return problems, 0
    node = shutil.which("node") or shutil.which("nodejs")
    if node is None:
        return ["node is not installed: it renders the formulas offline (Debian: apt-get install nodejs)"], 0
    unique = sorted(set(formulas))
    run = subprocess.run([node, str(RENDERER), str(next(iter(mathjax)).parent)], input=json.dumps(unique),
                         capture_output=True, text=True, timeout=600)
    if run.returncode != 0:
        return [f"MathJax did not start offline: {run.stderr.strip()[-500:]}"], 0
    report = json.loads(run.stdout)
    pages_of = {}
    for formula, page in zip(formulas, where):
        pages_of.setdefault(formula[0], page)
    for tex, message in report["bad"]:
        problems.append(f"{pages_of.get(tex, '?')}: MathJax cannot typeset {html.escape(tex)[:120]!r}: {message}")
    return problems, report["rendered"]


def main(argv: list[str]) -> int:
    if len(argv) != 1:
        print("usage: python scripts/check_offline_math.py docs/_build/html", file=sys.stderr)
        return 2
    problems, rendered = check(Path(argv[0]))
    for problem in problems:
        print(f"check_offline_math: {problem}", file=sys.stderr)
    if problems:
        return 1
    print(f"check_offline_math: no page loads anything from another host; {rendered} distinct formulas typeset "
          "offline by the site's own MathJax")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
