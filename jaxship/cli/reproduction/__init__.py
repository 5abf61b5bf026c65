"""What `jaxship reproduce` and `jaxship autopilot` run (application layer, written
against the public API, `import jaxship as js`): the identification study of the
thesis, chapter 4 (`thesis`), the whole thesis pipeline behind `jaxship reproduce`
(`reproduce`, its report `reproduce_report`, the records of its discovery case
`discovery_case`), and the heading autopilot of chapter 5 behind `jaxship autopilot`
(`autopilot`, `autopilot_thesis`). The notebooks show its pieces
(`from jaxship.cli.reproduction import thesis`). Studies that no command runs live
outside the package, in `benchmarks/studies/`."""
