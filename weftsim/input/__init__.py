"""Scene and parameters: what a run is given.

:mod:`weftsim.input.scene` reads a scene file (TOML, units in the key names, ``extends``, the bundled
scenes) against the schema of :mod:`weftsim.input.schema` (every key, its unit, range and place) into the
frozen SI dataclasses of :mod:`weftsim.input.params`; :mod:`weftsim.input.joint_keys` says which keys joint F
takes from joint E and which describe a joint that is ideal in the scene.
"""
