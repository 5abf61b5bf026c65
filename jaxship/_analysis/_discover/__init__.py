"""Discovery of missing effects (`jaxship.discover`)."""
