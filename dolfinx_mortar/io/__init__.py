"""Output and input: crash-safe XDMF series, gmsh files, result files."""
