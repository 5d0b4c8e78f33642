"""The nonlinear problem (user form + contact), Newton, its line search and convergence
tests, and the load-path driver."""
