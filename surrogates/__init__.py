"""The default fitted surrogate(s) as JSON, reproducible with `designer fit` on the bundled table."""
