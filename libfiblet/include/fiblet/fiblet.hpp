// fiblet — compress MRtrix3 .tck tractograms into fiblets (.fft) and decode
// them fast. Umbrella header: the whole public API.
//
//   error.hpp          fiblet::Error and its categories
//   tck.hpp            streaming .tck reader, atomic .tck writer
//   fft_format.hpp     the .fft layout: header, LUT, blocks, trailer
//   fft_file.hpp       validated .fft reading (header + LUT up front, blocks on demand)
//   checksum.hpp       XXH64 integrity chunk of .fft files, whole-file verification
//   direction_code.hpp the 8-bit direction code and its frames
//   encode.hpp         one streamline -> blocks (closed loop)
//   compress.hpp       the whole .tck -> .fft pipeline
//   decode.hpp         blocks -> points (scalar reference), fibers -> TRX-layout arrays
//   compare.hpp        a .fft measured against its source .tck
//   error_stats.hpp    max / mean / RMS / percentiles of position errors
//   geometry_error.hpp decoded vs input both ways, endpoints, lengths
//   fiber_ends.hpp     the ENDS chunk: fibers end where their input does
//   resample.hpp       fixed-step resampling, point-to-polyline distance
//   view.hpp           camera, frustum, level of detail, block bounding spheres
//   block_index.hpp    per-block boxes (BIDX chunk) and a hierarchy over them
//   select.hpp         selective decoding: fiber subsets, regions, frustum, LoD
//   fft_subset.hpp     a selection written as a smaller .fft file
//   output_file.hpp    atomic outputs, cleanup on signals
#pragma once

#include "fiblet/block_index.hpp"
#include "fiblet/checksum.hpp"
#include "fiblet/compare.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/direction_code.hpp"
#include "fiblet/encode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/error_stats.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/fft_format.hpp"
#include "fiblet/fft_subset.hpp"
#include "fiblet/fiber_ends.hpp"
#include "fiblet/geometry.hpp"
#include "fiblet/geometry_error.hpp"
#include "fiblet/output_file.hpp"
#include "fiblet/resample.hpp"
#include "fiblet/select.hpp"
#include "fiblet/tck.hpp"
#include "fiblet/view.hpp"
