"""Output and input: crash-safe XDMF series, gmsh files, merged meshes, result files."""
