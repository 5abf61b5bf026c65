"""The workflows behind the commands, as library verbs: identification from records
(`_identify`: the model catalogue, start values, the assessment, the selection, the
result file), the standard trials sized for a vessel (`_trials`), the IMO check with its
band (`_imo`) and the autopilot's design rules and evaluation (`_autopilot`). They are
written against the public API (`import jaxship as js`) and re-exported by
`jaxship/__init__.py`, which imports them last."""
