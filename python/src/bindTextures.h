#pragma once
// Texture and image bindings of eyerender._hdeye (bindTextures.cpp).
#include <nanobind/nanobind.h>

void BindTextures(nanobind::module_& m);
