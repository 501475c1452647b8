"""beamfx: geometrically exact (Simo–Reissner) 3D beams on FEniCSx / DOLFINx 0.5.2.

Layers, each importing only those below it: geometry, physics, solvers, analyses, io, scene,
bench, cli. Import the submodules you need; this package module stays light so that
``import beamfx`` never pulls in DOLFINx or PETSc.
"""

__version__ = "0.1.0"
