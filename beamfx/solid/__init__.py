"""The 3D solid of the same beam, for comparison: gmsh sweep (geometry), energies and end
tractions (model), static and modal solves (solve), ``beamfx solid`` (run)."""
