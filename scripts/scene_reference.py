"""Print the scene-file key reference (Markdown) from weftsim.input.schema.SCHEMA, for the README."""

import dataclasses

from weftsim.input.params import Lubrication, RapierTape, Scene
from weftsim.input.scene import SCHEMA, to_file_keys


def main() -> None:
    # The lubrication tables are optional (absent: the dry joint); their defaults are those of a table given
    # with its one required key.
    lubricated = dataclasses.replace(Scene().joint, lubrication=Lubrication(viscosity=0.0))
    joint_f = dataclasses.replace(Scene().joint_f, lubrication=lubricated.lubrication)
    # [rapier_tape] is optional too (absent: the rigid rapier); its defaults are those of an empty table.
    scene = dataclasses.replace(Scene(), joint=lubricated, joint_f=joint_f, rapier_tape=RapierTape())
    defaults = to_file_keys(scene)
    print("| key | default | allowed | meaning |")
    print("|---|---|---|---|")
    for key in SCHEMA:
        value = defaults[key.path]
        if key.path.endswith("lubrication.housing_heat_transfer_w_k"):
            value = "estimated"
        elif value is None or value == "" or (key.path.endswith(("oil.nu40_mm2_s", "oil.nu100_mm2_s")) and not value):
            value = "not set"  # an optional key without a default
        elif key.path.endswith("lubrication.viscosity_mpa_s"):
            value = "required in the table, or oil"
        elif isinstance(value, float):
            value = f"{value:.6g}"
        elif isinstance(value, list):
            value = "[" + ", ".join(f"{v:.6g}" for v in value) + "]"
        print(f"| `{key.path}` | {value} | {key.allowed()} | {key.doc} |")


if __name__ == "__main__":
    main()
