"""The continuum-based (ANCF-style) beam: centre line and two section vectors as fields, a
St Venant–Kirchhoff energy integrated over the section (model), static and modal solves
(solve). Between the Reissner beam and the 3D solid, for comparison (docs/continuum.md)."""
