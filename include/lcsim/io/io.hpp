// The I/O layer: file formats only. Readers validate what they read and throw
// InputError whose message names the file, the key and the value; writers
// produce files whole or not at all. One header per format; this one
// includes them all.
#pragma once

#include <lcsim/io/atomic_output.hpp>
#include <lcsim/io/csv.hpp>
#include <lcsim/io/input_error.hpp>
#include <lcsim/io/json.hpp>
#include <lcsim/io/lcp_file.hpp>
#include <lcsim/io/model_file.hpp>
#include <lcsim/io/sensitivity.hpp>
#include <lcsim/io/text.hpp>
#include <lcsim/io/yaml.hpp>
