"""The fading model of the paper (Sections 3-5): light spectra, colourants and recipes, Kubelka-Munk layers, the fluxes, time stepping, the mixture grid and unmixing."""
