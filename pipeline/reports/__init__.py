"""Reports and figures: table columns and formats, the design table, the HTML report, the output
files and paths, and the plots.  Imports neither :mod:`pipeline.batch` nor :mod:`pipeline.commands`."""
