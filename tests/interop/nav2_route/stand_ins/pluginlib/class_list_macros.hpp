#pragma once
// Stand-in for pluginlib: the test constructs the loader directly, so exporting is a no-op.
#define PLUGINLIB_EXPORT_CLASS(class_type, base_type) \
  static_assert(sizeof(class_type) > 0, "exported plugin class must be complete");
