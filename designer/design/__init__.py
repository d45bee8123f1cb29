"""Design decisions: goals on k and c, the suggestion search and its ranking, and the next prints to
make on an unknown printer. Imports the model, the study and the foundation."""
