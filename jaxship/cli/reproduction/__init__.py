"""`jaxship reproduce`: the whole thesis pipeline (`reproduce`) and its report
(`reproduce_report`). The study it runs is the library's `jaxship.thesis`."""
