"""The study: the six print factors and their printable space, coefficient tables (the bundled
Box-Behnken study and a user's runs), the design of experiments, and the study's statistics
(MANOVA/ANOVA). Imports only the foundation (`errors`, `units`, `files`, `keys`)."""
