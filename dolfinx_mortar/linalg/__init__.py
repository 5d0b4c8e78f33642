"""Linear algebra of the Newton step: the linear solver's choice, the contact block
preconditioner, the near-nullspace of rigid-body modes, and sparse matrix products."""
