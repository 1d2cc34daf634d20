"""The README's figure of a worn joint E on the `loom` at 600 rpm: docs/img/loom-worn-joint.png.

``PYTHONPATH=. python scripts/loom_worn_figure.py``: the new joint (c = 0.02 mm) against worn ones
(0.1 and 0.25 mm), two revolutions on the default engine each, the six channels of revolution 2
(weftsim.post.plots.plot_channels).  Revolution 2 is one draw of the impact sequence (docs/physics.md
section 6): its single peaks are an illustration; the loads table (scripts/loom_loads_table.py) gives
the means.
"""

from pathlib import Path

import weftsim
from weftsim.post.plots import plot_channels

ROOT = Path(__file__).resolve().parents[1]
CLEARANCES_MM = (0.02, 0.1, 0.25)


def main():
    results = []
    for c in CLEARANCES_MM:
        result = weftsim.simulate(weftsim.load_scene("loom", clearance_mm=c, revolutions=2))
        assert result.ok, result.message
        results.append(result)
    labels = [f"c = {c:g} mm" + (" (new)" if i == 0 else " (worn)") for i, c in enumerate(CLEARANCES_MM)]
    fig = plot_channels(results, labels, "loom at 600 rpm: a new and a worn joint E (revolution 2)")
    out = ROOT / "docs" / "img" / "loom-worn-joint.png"
    fig.savefig(out, dpi=100)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
