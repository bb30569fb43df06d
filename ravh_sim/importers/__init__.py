"""Offline converters that write the files the simulator reads: the upstream houses (``houses``), the
Sweet Home 3D furniture catalogues (``furniture``). Nothing in the runtime imports them."""
