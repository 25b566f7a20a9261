"""Our numbers next to the published ones: the data of the sources (`published`), the row providers of each link
(`bearing_rows`, `radiation_rows`, `source_rows`) and `housingfe validate` (`validate`)."""
