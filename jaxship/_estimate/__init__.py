"""Estimation: parameter metadata, prediction-error fits, start values. Public names are
re-exported from `jaxship` (import the submodules directly inside the package)."""
