"""Print the scene-file key reference (Markdown) from weftsim.scene.SCHEMA, for the README."""

from weftsim.params import Scene
from weftsim.scene import SCHEMA, to_file_keys


def main() -> None:
    defaults = to_file_keys(Scene())
    print("| key | default | allowed | meaning |")
    print("|---|---|---|---|")
    for key in SCHEMA:
        value = defaults[key.path]
        if value is None:  # an optional key without a default
            value = "not set"
        elif isinstance(value, float):
            value = f"{value:.6g}"
        elif isinstance(value, list):
            value = "[" + ", ".join(f"{v:.6g}" for v in value) + "]"
        print(f"| `{key.path}` | {value} | {key.allowed()} | {key.doc} |")


if __name__ == "__main__":
    main()
