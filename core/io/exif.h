#pragma once
// A minimal EXIF reader and writer: only the tags photogrammetry needs (camera identity, focal length,
// orientation, sensor geometry, and for the reader the exposure settings). Every read is bounds-checked against the block it came from;
// a malformed block never fails a caller, it yields present=false (or the fields read before
// the damage) plus a human-readable `warning`.
#include <string>
#include <string_view>

namespace reconar {

struct ExifInfo {
  bool present = false;  // a TIFF header and IFD0 were parsed
  std::string make;
  std::string model;
  double focal_length_mm = 0;    // FocalLength (0x920A); 0 when absent
  double focal_length_35mm = 0;  // FocalLengthIn35mmFilm (0xA405); 0 when absent
  int orientation = 1;           // 1..8 as in the EXIF spec; 1 when absent or invalid
  // FocalPlaneX/YResolution (0xA20E/0xA20F): pixels per `focal_plane_resolution_unit`.
  double focal_plane_x_resolution = 0;
  double focal_plane_y_resolution = 0;
  int focal_plane_resolution_unit = 2;  // 2 = inch (EXIF default), 3 = centimetre
  int pixel_x_dimension = 0;            // PixelXDimension (0xA002); may disagree with the pixels
  int pixel_y_dimension = 0;            // PixelYDimension (0xA003)
  // The exposure settings (read, not written): 0 when absent.
  double exposure_time_s = 0;  // ExposureTime (0x829A), seconds
  double f_number = 0;         // FNumber (0x829D)
  int iso = 0;                 // ISOSpeedRatings (0x8827), the first value
  std::string warning;                  // why (part of) the block was ignored; empty if clean
};

// Parses a TIFF-structured EXIF block (starting with "II*\0" or "MM\0*").
ExifInfo ParseExifTiff(std::string_view tiff);

// Parses the payload of a JPEG APP1 segment: "Exif\0\0" followed by the TIFF block.
ExifInfo ParseExifApp1(std::string_view app1_payload);

// Walks a JPEG's marker segments up to the first SOS looking for an EXIF APP1 segment,
// without decoding pixels. Non-JPEG or damaged input yields present=false (+ warning).
ExifInfo ReadExifFromJpeg(std::string_view jpeg_bytes);

// The payload of a JPEG APP1 segment ("Exif\0\0" and a little-endian TIFF block) holding the
// fields of `info` that are set (make, model, orientation, focal length, its 35 mm equivalent,
// the pixel dimensions, the focal-plane resolution); ParseExifApp1 reads them back. Rationals are
// written to four decimals, FocalLengthIn35mmFilm rounded to a whole millimetre (it is a SHORT).
std::string BuildExifApp1(const ExifInfo& info);

}  // namespace reconar
