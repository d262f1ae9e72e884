"""The thesis's study, bundled: subjects (manifests), and the findings to check them against."""
