"""The housing as solid finite elements: the FE model of a scene (mesh, space, supports, K and M) and
loads on its surfaces."""
