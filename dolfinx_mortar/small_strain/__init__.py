"""Small-strain models built on the library: linear elasticity (plane and 3D) and its
axisymmetric form, with ContactProblem, the short path from a mesh to a contact solve."""
