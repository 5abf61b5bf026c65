"""The studies behind the commands (application layer, written against the public API,
`import jaxship as js`): the identification study of the thesis, chapter 4 (`thesis`),
the whole thesis pipeline behind `jaxship reproduce` (`reproduce`, `reproduce_report`),
the heading autopilot of chapter 5 behind `jaxship autopilot` (`autopilot`), the
records with hidden effects of `reproduce`'s discovery part (`discovery`), and Lu &
Zhao's discrete response models (`svm`, which needs the discrete coefficients that only
the estimator's internals carry)."""
