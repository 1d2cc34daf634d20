"""Check the links of a built HTML site: every ``page.html#anchor`` inside the site must name an id of that page.

Sphinx does not check the fragments of its own links: the source pages' links back to the API reference
(viewcode) pointed at ids that did not exist (``select_model``, ``rigid_body_needs``; issue 25).
``scripts/build_docs.sh`` runs this after every build; a broken anchor fails the build, as a warning does.

Usage: python scripts/check_anchors.py docs/_build/html
"""

from __future__ import annotations

import sys
from html.parser import HTMLParser
from pathlib import Path


class _Page(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.ids: set[str] = set()
        self.links: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        values = dict(attrs)
        if values.get("id"):
            self.ids.add(values["id"])
        if tag == "a" and values.get("name"):
            self.ids.add(values["name"])
        href = values.get("href") if tag == "a" else None
        if href and "#" in href and "://" not in href and not href.startswith("mailto:"):
            self.links.append(href)


def broken_anchors(root: Path) -> list[tuple[str, str]]:
    """(page, href) of every link to an id that its target page inside ``root`` lacks, sorted."""
    pages = {}
    for path in root.rglob("*.html"):
        page = _Page()
        page.feed(path.read_text(errors="replace"))
        pages[path.resolve()] = (path, page)
    broken = set()
    for source, page in pages.values():
        for href in page.links:
            target, _, fragment = href.partition("#")
            resolved = (source.parent / target).resolve() if target else source.resolve()
            if fragment and resolved in pages and fragment not in pages[resolved][1].ids:
                broken.add((str(source.relative_to(root)), href))
    return sorted(broken)


def main(argv: list[str]) -> int:
    if len(argv) != 1 or not Path(argv[0]).is_dir():
        print("usage: python scripts/check_anchors.py BUILT_HTML_DIRECTORY", file=sys.stderr)
        return 2
    broken = broken_anchors(Path(argv[0]))
    for page, href in broken:
        print(f"check_anchors: {page}: link to a missing anchor: {href}", file=sys.stderr)
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
