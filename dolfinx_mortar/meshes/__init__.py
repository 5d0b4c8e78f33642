"""Operations on meshes: merging two bodies' meshes into one, and the partitioner that
spreads the contact surfaces over the ranks."""
