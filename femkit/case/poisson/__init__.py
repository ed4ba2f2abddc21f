"""``problem: poisson`` case files: schema, the one Poisson pipeline (``run``), outputs and the
``femkit check`` cross-check against scikit-fem and pyamg (``cross_check``)."""
