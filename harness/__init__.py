"""Python harness of the icoac controller: ctypes binding of libicoac_sim, grid runs, results, figures."""
__version__ = "0.1.0"
