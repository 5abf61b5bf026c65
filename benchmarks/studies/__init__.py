"""Studies that reproduce published results with jaxship, written against the public
API only (`import jaxship as js`): Astrom & Kallstrom's identification from zig-zags with
disturbances (`astrom`) and identification on the measured Esso Osaka and HSVA KVLCC2
data (`real_data`). They are the application, outside the package: the notebooks, the
benchmark scripts and the tests import them from the project root
(`from benchmarks.studies import real_data`)."""
