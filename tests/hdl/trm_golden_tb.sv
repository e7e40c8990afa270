// The decoder's golden vectors replayed in an HDL simulator: a clocked testbench in the scoreboard pattern a
// display-controller team uses, with the bit-accurate model (trm_decoder_model.sv, the C API through DPI-C) and a DUT
// slot beside it fed the same line stream.
//
// It lives under tests/ and not hw_models/: it is a test (run by ctest, reading tests/golden/), and it depends on the
// decoder, which itself depends on hw_models, so under hw_models/ the dependency would point the wrong way.
//
// What it checks, for one scene and panel of tests/golden/vectors.txt (+vectors=DIR of `trm vectors` output):
//   * the stimulus: each frame's link codes file hashes to its golden FNV-1a 64 (so the codes driven are the golden
//     scene's), and so does each expected drive file;
//   * the model: rows come out once each, in raster order, with the full width; every drive code equals the
//     `trm vectors` drive file's, and the hex text of what the model produced (the drive file's format, rebuilt
//     here from the codes) hashes to the golden hash: bit for bit what the command line wrote when it was checked in;
//   * the DUT slot: every row the DUT gives equals the model's row of the same view and index (the scoreboard),
//     whatever the latency, with its sink stalling at random so its backpressure is exercised.
// Until a team's RTL takes the slot (+define+TRM_DUT=their_module, same ports), a second model instance sits there.
//
// Plusargs: +vectors=DIR +golden=FILE +scene=NAME +panel=NAME +trm_config=DIR/report.json [+trm_dut_defect_row=Y]
`ifndef TRM_DUT
`define TRM_DUT trm_decoder_model
`endif

module trm_golden_tb;
  localparam int MAX_SAMPLES = 192;  // 64 pixels: the golden views are 24 wide
  localparam int MAX_LINES = 64;
  localparam int MAX_FRAMES = 8;
  localparam int TIMEOUT_CYCLES = 200000;
  localparam longint unsigned FNV_OFFSET = 64'hcbf29ce484222325;
  localparam longint unsigned FNV_PRIME = 64'h00000100000001b3;

  logic clk = 1'b0;
  logic rst_n = 1'b0;
  always #5 clk = ~clk;

  // ---- the checked-in golden hashes and the vector files -------------------------------------------------------
  longint unsigned golden [string];
  string vectors_dir, scene, panel;
  int frames;
  bit frame_reduced [MAX_FRAMES];
  int code_lines [MAX_FRAMES], code_samples [MAX_FRAMES];
  logic [15:0] codes [MAX_FRAMES][MAX_LINES][MAX_SAMPLES];
  int drive_lines [MAX_FRAMES], drive_samples [MAX_FRAMES];
  logic [15:0] expected [MAX_FRAMES][MAX_LINES][MAX_SAMPLES];
  int drive_digits;  // hex digits per drive word in the drive files

  // As a string: a conditional of two literals would be a bit vector, padded with spaces to the longer one.
  function automatic string parity_name(input bit reduced);
    if (reduced) return "reduced";
    return "full";
  endfunction

  function automatic int hex_value(input byte c);
    if (c >= "0" && c <= "9") return int'(c) - int'("0");
    if (c >= "a" && c <= "f") return int'(c) - int'("a") + 10;
    return -1;
  endfunction

  function automatic longint unsigned fnv_byte(input longint unsigned hash, input byte c);
    return (hash ^ longint'(c)) * FNV_PRIME;
  endfunction

  // The word in the vector files' form: lower-case hex, zero-padded to `digits`.
  function automatic longint unsigned fnv_word(input longint unsigned hash, input int value, input int digits);
    longint unsigned h = hash;
    for (int d = digits - 1; d >= 0; d--) begin
      int nibble = (value >> (4 * d)) & 15;
      h = fnv_byte(h, nibble < 10 ? byte'("0" + nibble) : byte'("a" + nibble - 10));
    end
    return h;
  endfunction

  function automatic void read_golden(input string path);
    int fd;
    string text, s, p, name;
    longint unsigned hash;
    fd = $fopen(path, "r");
    if (fd == 0) begin
      $fatal(1, "cannot open the golden hashes '%s'", path);
      return;
    end
    while ($fgets(text, fd) != 0) begin
      if (text.len() == 0 || text.getc(0) == "#") continue;
      if ($sscanf(text, "%s %s %s %h", s, p, name, hash) != 4) $fatal(1, "%s: malformed line '%s'", path, text);
      if (s == scene && p == panel) golden[name] = hash;
    end
    $fclose(fd);
  endfunction

  // Reads one `trm vectors` hex file into rows of words; returns its lines and words per line, and checks the file's
  // hash against the golden one.
  task automatic read_vector_file(input string name, input logic [$clog2(MAX_FRAMES)-1:0] frame, input bit is_drive,
                                  output int lines,
                                  output int samples);
    string path = {vectors_dir, "/", name};
    int fd;
    string text;
    longint unsigned hash = FNV_OFFSET;
    fd = $fopen(path, "r");
    lines = 0;
    samples = -1;
    if (fd == 0) begin
      $fatal(1, "cannot open the vector file '%s' (run `trm vectors` for %s %s)", path, scene, panel);
      return;
    end
    if (golden.exists(name) == 0) $fatal(1, "%s has no golden hash for %s %s", name, scene, panel);
    while ($fgets(text, fd) != 0) begin
      int words = 0, value = 0, digits = 0;
      if (lines == MAX_LINES) $fatal(1, "%s: more than %0d lines", path, MAX_LINES);
      for (int i = 0; i < text.len(); i++) begin
        byte c = text.getc(i);
        hash = fnv_byte(hash, c);
        if (hex_value(c) >= 0) begin
          value = value * 16 + hex_value(c);
          digits++;
        end else if (c == " " || c == "\n") begin
          if (digits == 0) $fatal(1, "%s line %0d: empty word", path, lines + 1);
          if (words == MAX_SAMPLES) $fatal(1, "%s line %0d: more than %0d words", path, lines + 1, MAX_SAMPLES);
          if (is_drive) begin
            expected[frame][lines][words] = 16'(value);
            drive_digits = digits;
          end else begin
            codes[frame][lines][words] = 16'(value);
          end
          words++;
          value = 0;
          digits = 0;
        end else begin
          $fatal(1, "%s line %0d: unexpected character %0d", path, lines + 1, c);
        end
      end
      if (samples >= 0 && words != samples) $fatal(1, "%s line %0d: %0d words, %0d above", path, lines + 1, words,
                                                   samples);
      samples = words;
      lines++;
    end
    $fclose(fd);
    if (hash != golden[name])
      $fatal(1, "%s hashes to %016h, the golden hash is %016h: the vectors are not the golden scene's", name, hash,
             golden[name]);
  endtask

  // Reads the golden hashes and every vector file of the scene; stops at the first problem, with its reason.
  task automatic load_vectors();
    string golden_path;
    if (!$value$plusargs("vectors=%s", vectors_dir) || !$value$plusargs("golden=%s", golden_path) ||
        !$value$plusargs("scene=%s", scene) || !$value$plusargs("panel=%s", panel))
    begin
      $fatal(1, "usage: +vectors=DIR +golden=FILE +scene=NAME +panel=NAME +trm_config=FILE");
      return;
    end
    read_golden(golden_path);
    frames = 0;
    for (int t = 0; t < MAX_FRAMES; t++) begin
      string full = $sformatf("frame_%03d_full_drive.hex", t), reduced = $sformatf("frame_%03d_reduced_drive.hex", t);
      if (golden.exists(full) == 0 && golden.exists(reduced) == 0) break;
      frame_reduced[t] = golden.exists(full) == 0;
      frames++;
    end
    if (frames == 0) begin
      $fatal(1, "%s lists no drive file for %s %s", golden_path, scene, panel);
      return;
    end
    for (int t = 0; t < frames; t++) begin
      string kind = parity_name(frame_reduced[t]);
      read_vector_file($sformatf("frame_%03d_%s_codes.hex", t, kind), 3'(t), 1'b0, code_lines[t], code_samples[t]);
      read_vector_file($sformatf("frame_%03d_%s_drive.hex", t, kind), 3'(t), 1'b1, drive_lines[t], drive_samples[t]);
    end
    $display("trm_golden_tb: %s %s, %0d frames of %0dx%0d, vector files match their golden hashes", scene, panel,
             frames, drive_samples[0] / 3, drive_lines[0]);
  endtask

  initial load_vectors();

  // ---- the line stream, the same for the model and the DUT (a valid each, the data shared) -----------------------
  logic        model_in_valid, dut_in_valid, in_first, in_kind, in_eye, in_intact;
  logic [31:0] in_index;
  logic [15:0] in_full_width, in_full_height, in_samples;
  logic [MAX_SAMPLES-1:0][15:0] in_codes;
  logic        model_in_ready, dut_in_ready;
  bit          stimulus_done = 1'b0;

  initial begin
    model_in_valid = 1'b0;
    dut_in_valid = 1'b0;
    in_first = 1'b0;
    in_kind = 1'b0;
    in_eye = 1'b0;
    in_intact = 1'b1;
    in_index = 0;
    in_full_width = 0;
    in_full_height = 0;
    in_samples = 0;
    in_codes = '0;
    repeat (4) @(posedge clk);
    rst_n <= 1'b1;
    for (int t = 0; t < frames; t++) begin
      for (int y = 0; y < code_lines[t]; y++) begin
        bit model_took = 1'b0, dut_took = 1'b0;
        @(posedge clk);
        model_in_valid <= 1'b1;
        dut_in_valid <= 1'b1;
        in_first <= y == 0;
        in_kind <= frame_reduced[t];
        in_index <= 32'(t);
        in_full_width <= 16'(drive_samples[t] / 3);
        in_full_height <= 16'(drive_lines[t]);
        in_samples <= 16'(code_samples[t]);
        for (int i = 0; i < MAX_SAMPLES; i++) in_codes[i] <= codes[t][y][i];
        // The line stays offered to each side until that side has taken it (valid and ready at one edge), so the
        // model and the DUT each take every line exactly once, each at its own pace.
        do begin
          @(posedge clk);
          if (model_in_valid && model_in_ready) begin
            model_took = 1'b1;
            model_in_valid <= 1'b0;
          end
          if (dut_in_valid && dut_in_ready) begin
            dut_took = 1'b1;
            dut_in_valid <= 1'b0;
          end
        end while (!(model_took && dut_took));
      end
    end
    stimulus_done = 1'b1;
  end

  // ---- the model and the DUT slot -------------------------------------------------------------------------------
  logic        model_out_valid, model_out_last, dut_out_valid, dut_out_last, dut_out_ready;
  logic [15:0] model_out_row, model_out_samples, dut_out_row, dut_out_samples;
  logic [MAX_SAMPLES-1:0][15:0] model_out_drive, dut_out_drive;

  trm_decoder_model #(.MAX_SAMPLES(MAX_SAMPLES)) model (
      .clk, .rst_n, .in_valid(model_in_valid), .in_ready(model_in_ready), .in_first, .in_kind, .in_eye, .in_index,
      .in_full_width,
      .in_full_height, .in_intact, .in_samples, .in_codes, .out_valid(model_out_valid), .out_ready(1'b1),
      .out_row(model_out_row), .out_last(model_out_last), .out_samples(model_out_samples),
      .out_drive(model_out_drive));

  `TRM_DUT #(.MAX_SAMPLES(MAX_SAMPLES)) dut (
      .clk, .rst_n, .in_valid(dut_in_valid), .in_ready(dut_in_ready), .in_first, .in_kind, .in_eye, .in_index,
      .in_full_width,
      .in_full_height, .in_intact, .in_samples, .in_codes, .out_valid(dut_out_valid), .out_ready(dut_out_ready),
      .out_row(dut_out_row), .out_last(dut_out_last), .out_samples(dut_out_samples), .out_drive(dut_out_drive));

  // The DUT's sink stalls about one cycle in four (a 16-bit Fibonacci LFSR, taps 16 14 13 11).
  logic [15:0] lfsr = 16'hace1;
  always @(posedge clk) lfsr <= {lfsr[14:0], lfsr[15] ^ lfsr[13] ^ lfsr[12] ^ lfsr[10]};
  assign dut_out_ready = lfsr[1:0] != 2'b00;

  // ---- the scoreboard -------------------------------------------------------------------------------------------
  int model_view = 0, model_next_row = 0, dut_view = 0, dut_next_row = 0;
  int dut_defect_row = -1;
  initial if (!$value$plusargs("trm_dut_defect_row=%d", dut_defect_row)) dut_defect_row = -1;
  longint unsigned model_hash = FNV_OFFSET;
  int code_mismatches = 0, hash_mismatches = 0, rows_checked = 0, dut_rows_compared = 0, dut_mismatches = 0;
  logic [15:0] model_rows [MAX_FRAMES][MAX_LINES][MAX_SAMPLES];
  logic [15:0] dut_rows [MAX_FRAMES][MAX_LINES][MAX_SAMPLES];
  bit model_has [MAX_FRAMES][MAX_LINES];
  bit dut_has [MAX_FRAMES][MAX_LINES];

  function automatic void compare_dut_row(input int v, input int y);
    int differ = 0;
    for (int i = 0; i < drive_samples[v]; i++) if (dut_rows[v][y][i] != model_rows[v][y][i]) differ++;
    if (differ != 0) begin
      $display("trm_golden_tb: ERROR: view %0d row %0d: the DUT differs from the model in %0d of %0d samples",
               v, y, differ,
             drive_samples[v]);
      dut_mismatches++;
    end
    dut_rows_compared++;
  endfunction

  always @(posedge clk) begin
    if (rst_n && model_out_valid) begin
      int v = model_view, y = int'(model_out_row);
      if (v >= frames) $fatal(1, "model: a row after the last view");
      if (y != model_next_row) $fatal(1, "model: view %0d gave row %0d where row %0d was due", v, y, model_next_row);
      if (int'(model_out_samples) != drive_samples[v])
        $fatal(1, "model: view %0d row %0d has %0d samples, the drive file %0d", v, y, model_out_samples,
               drive_samples[v]);
      if (model_out_last != (y == drive_lines[v] - 1)) $fatal(1, "model: out_last wrong at view %0d row %0d", v, y);
      for (int i = 0; i < drive_samples[v]; i++) begin
        if (model_out_drive[i] != expected[v][y][i]) begin
          if (code_mismatches < 10)
            $display("trm_golden_tb: ERROR: view %0d row %0d sample %0d: model drive code %0d, vector file %0d",
                     v, y, i,
                   model_out_drive[i], expected[v][y][i]);
          code_mismatches++;
        end
        model_hash = fnv_word(model_hash, int'(model_out_drive[i]), drive_digits);
        model_hash = fnv_byte(model_hash, i == drive_samples[v] - 1 ? 8'h0a : 8'h20);
        model_rows[v][y][i] = model_out_drive[i];
      end
      model_has[v][y] = 1'b1;
      if (dut_has[v][y]) compare_dut_row(v, y);
      rows_checked++;
      model_next_row = y + 1;
      if (model_out_last) begin
        string name = $sformatf("frame_%03d_%s_drive.hex", v, parity_name(frame_reduced[v]));
        if (model_hash != golden[name]) begin
          $display("trm_golden_tb: ERROR: model: view %0d's drive codes hash to %016h, %s's golden hash is %016h", v,
                   model_hash, name, golden[name]);
          hash_mismatches++;
        end else
          $display("trm_golden_tb: %s matches its golden hash %016h", name, model_hash);
        model_hash = FNV_OFFSET;
        model_view++;
        model_next_row = 0;
      end
    end
    if (rst_n && dut_out_valid && dut_out_ready) begin
      int v = dut_view, y = int'(dut_out_row);
      if (v >= frames) $fatal(1, "DUT: a row after the last view");
      if (y != dut_next_row) $fatal(1, "DUT: view %0d gave row %0d where row %0d was due", v, y, dut_next_row);
      if (int'(dut_out_samples) != drive_samples[v])
        $fatal(1, "DUT: view %0d row %0d has %0d samples, expected %0d", v, y, dut_out_samples, drive_samples[v]);
      for (int i = 0; i < drive_samples[v]; i++) dut_rows[v][y][i] = dut_out_drive[i];
      // +trm_dut_defect_row=Y: the DUT's row Y of the first view arrives with one code off by one, to show the
      // scoreboard fails a DUT that differs in a single code.
      if (v == 0 && y == dut_defect_row) dut_rows[v][y][0] = dut_rows[v][y][0] ^ 16'd1;
      dut_has[v][y] = 1'b1;
      if (model_has[v][y]) compare_dut_row(v, y);
      dut_next_row = y + 1;
      if (dut_out_last) begin
        dut_view++;
        dut_next_row = 0;
      end
    end
  end

  // ---- the end ----------------------------------------------------------------------------------------------------
  int cycles = 0;
  always @(posedge clk) begin
    cycles <= cycles + 1;
    if (cycles > TIMEOUT_CYCLES)
      $fatal(1, "timeout: after %0d cycles the model has %0d and the DUT %0d of %0d views", cycles, model_view,
             dut_view, frames);
    if (stimulus_done && model_view == frames && dut_view == frames) begin
      int rows_expected = 0;
      for (int t = 0; t < frames; t++) rows_expected += drive_lines[t];
      if (rows_checked != rows_expected || dut_rows_compared != rows_expected)
        $fatal(1, "%0d model rows checked, %0d DUT rows compared, %0d expected", rows_checked, dut_rows_compared,
               rows_expected);
      if (code_mismatches != 0 || hash_mismatches != 0 || dut_mismatches != 0)
        $fatal(1, "FAIL: %0d codes differ from the vectors, %0d views from their golden hash, %0d DUT rows from the model",
               code_mismatches, hash_mismatches, dut_mismatches);
      $display("trm_golden_tb: PASS %s %s: %0d views, %0d rows, every drive code and golden hash identical; DUT slot",
               scene, panel, frames, rows_checked);
      $display("trm_golden_tb:   %0d rows identical to the model's; %0d cycles", dut_rows_compared, cycles);
      $finish;
    end
  end
endmodule
