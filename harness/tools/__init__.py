"""Developer tools of the harness that need neither the shared library nor the harness modules."""
