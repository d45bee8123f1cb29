"""The model: the response surface of c and k over the six factors (forms, ridge fit, selection by
leave-one-out, nested validation), its predictive distribution, and its calibration to a user's
printer. Imports the study and the foundation."""
