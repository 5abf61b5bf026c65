"""Studies that reproduce published results with jaxship, written against the public
API only (`import jaxship as js`), that the notebooks, the benchmark scripts and the tests
share: Astrom & Kallstrom's identification from zig-zags with disturbances (`astrom`),
the hidden-effect data sets of `discover` (`discovery`), the published train/test splits
of the measured Esso Osaka and KVLCC2 data (`published_splits`), identification on those
measured data (`real_data`), the KVLCC2 preset against the SIMMAN 2008 free-running
tests (`kvlcc2_simman`) and Lu & Zhao's discrete response models with the design of
experiments (`svm`).

A public namespace that `import jaxship` does not load: import a study by name,
`from jaxship.studies import real_data`. The measured data are not part of the package
(`jaxship.shared_data_dir()`)."""
