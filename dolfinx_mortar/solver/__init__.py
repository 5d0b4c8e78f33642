"""The nonlinear problem (user form + contact), Newton, and the load-path driver."""
