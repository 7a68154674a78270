#pragma once
// Drawing primitives on RGB images (image/image.h): pixels, lines, discs, rings and text
// in a built-in 5x7 pixel font. Everything is clipped to the image; colours are written
// as they are (no blending, no antialiasing), so pictures are exact functions of their
// inputs. Contact sheets, label overlays and line plots draw with these only.
// Coordinates are pixel centres (image/image.h): (0, 0) is the top-left pixel's centre.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>

#include "image/image.h"

namespace handlabel {

using Rgb = std::array<uint8_t, 3>;

// Paints pixel (x, y) of a 3-channel image; does nothing outside the image.
void SetPixel(ImageU8* image, int x, int y, const Rgb& color);

// Paints steps + 1 evenly spaced samples from a to b (both ends included), each rounded
// to the nearest pixel and painted as a thickness x thickness square with that pixel at
// its top-left corner. steps = 0 paints a alone.
void DrawLineSamples(ImageU8* image, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                     int steps, const Rgb& color, int thickness = 1);

// A line with one sample per pixel along its longer axis (ceil(max(|dx|, |dy|)) steps).
void DrawLine(ImageU8* image, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
              const Rgb& color, int thickness = 1);

// A line `width` pixels wide with round ends: discs of radius width / 2 at most one
// pixel apart. Lines over 4 x (width + height) long are skipped (an end projected near
// infinity would otherwise take forever to draw).
void DrawThickLine(ImageU8* image, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                   double width, const Rgb& color);

// The pixels within `radius` (centre to centre) of the pixel nearest to `center`.
void DrawDisc(ImageU8* image, const Eigen::Vector2d& center, double radius,
              const Rgb& color);

// The disc's outer pixel ring: distance from the centre pixel in [radius - 1, radius].
void DrawRing(ImageU8* image, const Eigen::Vector2d& center, int radius,
              const Rgb& color);

// The built-in font: 5 x 7 pixel glyphs for digits, A-Z and . , - + : / ( ) % _ =;
// other characters leave a blank. Each glyph takes kFontAdvance pixels of width.
inline constexpr int kFontGlyphWidth = 5;
inline constexpr int kFontGlyphHeight = 7;
inline constexpr int kFontAdvance = 6;

// Draws `text` (ASCII; lower case is drawn as upper case) with its top-left corner at
// (x, y), each font pixel `scale` x `scale`.
void DrawText(ImageU8* image, int x, int y, const std::string& text, const Rgb& color,
              int scale = 1);

}  // namespace handlabel
