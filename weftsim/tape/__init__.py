"""The flexible rapier tape (docs/rapier-tape.md): its Ritz model's matrices and parameter block
(:mod:`.model`), the choice between it and the rigid rapier (:mod:`.selection`) and its output channels
(:mod:`.channels`).  The equations are in :mod:`weftsim.kernel.tape`."""
