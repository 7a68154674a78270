#pragma once
// The one rule both pictures of masks draw outlines by (contact_sheet, mask_sheet).

namespace handlabel {

// True where on(x, y) holds and one of its four neighbours does not; `on` decides
// what lies outside the picture.
template <typename On>
bool OnMaskOutline(const On& on, int x, int y) {
  return on(x, y) && !(on(x - 1, y) && on(x + 1, y) && on(x, y - 1) && on(x, y + 1));
}

}  // namespace handlabel
