"""Classical-elasticity FEM references (scikit-fem); never imports pdverify."""
