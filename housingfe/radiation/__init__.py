"""Sound radiation (van Roosmalen 1994, Sec. 4.7, Appendix E): analytic radiators, Föller's box model,
numerical radiation efficiency from a surface velocity field, sound power levels (eq. 4.16)."""
