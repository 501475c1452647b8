"""Scripts for ParaView's own Python (``pvpython``), shipped with beamfx but never imported by it.

They live in their own folder because pvpython puts a script's folder first on ``sys.path``,
where a beamfx module of the same name (there was a ``beamfx/io/paraview.py``) would shadow
ParaView's ``paraview`` package.

* ``open_in_paraview.py``: the view of a results folder; ``beamfx run`` copies it there.
* ``pvcheck.py``: reads the results back in ParaView, checks them and renders a picture.
"""
