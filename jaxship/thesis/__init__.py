"""The thesis' study (Ødegård 2009) that `jaxship reproduce` runs and the notebooks show:
the identification of chapter 4 on simulated records (`jaxship.thesis.identification`),
the heading autopilots of chapter 5 (`jaxship.thesis.autopilot`) and the records of the
discovery case (`jaxship.thesis.discovery_case`). Import the submodules explicitly
(`from jaxship.thesis import identification`); `import jaxship` does not load them."""
