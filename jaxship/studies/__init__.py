"""Studies that reproduce published results with jaxship, written against the public
API only (`import jaxship as js`) so that they double as worked examples: the
identification study of the thesis, chapter 4 (`thesis`), the whole thesis pipeline
behind `jaxship reproduce` (`reproduce`), identification on the measured Esso Osaka and
HSVA KVLCC2 data (`real_data`), Lu & Zhao's discrete response models with an
experiment-design comparison by Cramer-Rao bounds (`svm`), and the heading autopilot of the
thesis, chapter 5, behind `jaxship autopilot` (`autopilot`). Import a study module
explicitly, e.g. `from jaxship.studies import thesis`."""
