"""Reports: pictures and tables made from graphs, worlds and run directories."""
