"""A plugin module that fails to import: reported only when a scenario uses it."""

import a_module_that_does_not_exist  # noqa: F401
