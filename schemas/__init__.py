"""Machine-readable schemas of the masonryfw data format (one JSON file per dataset kind)."""
