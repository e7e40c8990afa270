// The bit-accurate trm decoder (the C API of decoder/include/trm/trm_c.h through DPI-C, trm_dpi.cpp) as a clocked
// line-stream block: the golden model a display-controller RTL is checked against, with the same ports a DUT would
// have. One input line per accepted cycle (valid/ready), one output row per accepted cycle (valid/ready). A line is a
// packed bus of MAX_SAMPLES 16-bit words, R G B interleaved, word 0 the leftmost pixel's R (an unpacked array port
// would do as well in the language, but Verilator 5.006 does not pass a timed process's writes through one).
//
// Each line carries the header of its view on the first line (in_first): kind (0 full, 1 reduced), eye, index t and
// the full view size. The view ends by itself after its last input line (the count the model's view shape gives),
// as a video stream's line count ends a frame; no separate end-of-view strobe is needed.
//
// in_ready falls while OUT_DEPTH rows are waiting: the model's output queue is bounded like an RTL line FIFO, so a
// sink that stalls backs the stream up instead of growing the queue without limit. It also stays low after a view's
// last line until all of that view's rows are out (the next view's first line would drop them).
module trm_decoder_model #(
    parameter int MAX_SAMPLES = 192,        // samples (3 per pixel) of the widest line
    parameter int OUT_DEPTH = 4,            // output rows held before in_ready falls
    parameter string CONFIG_PLUSARG = "trm_config"  // +trm_config=PATH: the decoder's JSON configuration
) (
    input  logic        clk,
    input  logic        rst_n,
    // input line stream
    input  logic        in_valid,
    output logic        in_ready,
    input  logic        in_first,
    input  logic        in_kind,
    input  logic        in_eye,
    input  logic [31:0] in_index,
    input  logic [15:0] in_full_width,
    input  logic [15:0] in_full_height,
    input  logic        in_intact,
    input  logic [15:0] in_samples,
    input  logic [MAX_SAMPLES-1:0][15:0] in_codes,
    // output row stream
    output logic        out_valid,
    input  logic        out_ready,
    output logic [15:0] out_row,
    output logic        out_last,
    output logic [15:0] out_samples,
    output logic [MAX_SAMPLES-1:0][15:0] out_drive
);
  import "DPI-C" function chandle trm_dpi_create(input string config_path);
  import "DPI-C" function void trm_dpi_destroy(input chandle h);
  import "DPI-C" function string trm_dpi_last_error(input chandle h);
  import "DPI-C" function int trm_dpi_begin_view(input chandle h, input int full_width, input int full_height,
                                                 input int kind, input int eye, input longint index);
  import "DPI-C" function int trm_dpi_view_shape(input chandle h, output int input_lines, output int input_samples,
                                                 output int output_lines, output int output_samples);
  import "DPI-C" function int trm_dpi_push_line(input chandle h, input int unsigned codes[], input int samples,
                                                input int intact);
  import "DPI-C" function int trm_dpi_end_view(input chandle h);
  import "DPI-C" function int trm_dpi_lines_ready(input chandle h, output int count);
  import "DPI-C" function int trm_dpi_pop_line(input chandle h, output int row, output int unsigned drive[],
                                               output int samples);

  localparam int TRM_OK = 0;

  chandle decoder;
  int input_lines, input_samples, output_lines, output_samples;
  int lines_pushed;
  int unsigned line_words [MAX_SAMPLES];
  int unsigned row_words [MAX_SAMPLES];

  // A refused call is a defect of the stream (or of the model): stop with the decoder's own message.
  function automatic void check(input int status, input string what);
    if (status < TRM_OK) $fatal(1, "trm_decoder_model: %s failed (status %0d): %s", what, status,
                                trm_dpi_last_error(decoder));
  endfunction

  initial begin
    string config_path;
    if (!$value$plusargs({CONFIG_PLUSARG, "=%s"}, config_path))
      $fatal(1, "trm_decoder_model: +%s=PATH (the decoder's JSON configuration) is required", CONFIG_PLUSARG);
    else decoder = trm_dpi_create(config_path);
    if (decoder == null) $fatal(1, "trm_decoder_model: %s", trm_dpi_last_error(null));
  end

  final trm_dpi_destroy(decoder);

  always @(posedge clk) begin
    int ready_rows, row, samples, status;
    if (!rst_n) begin
      in_ready <= 1'b0;
      out_valid <= 1'b0;
      lines_pushed = 0;
    end else begin
      if (in_valid && in_ready) begin
        if (in_first) begin
          if (lines_pushed != 0 && lines_pushed != input_lines)
            $fatal(1, "trm_decoder_model: a view began after %0d of the previous view's %0d lines", lines_pushed,
                   input_lines);
          check(trm_dpi_begin_view(decoder, int'(in_full_width), int'(in_full_height), int'(in_kind), int'(in_eye),
                                   longint'(in_index)), "begin_view");
          check(trm_dpi_view_shape(decoder, input_lines, input_samples, output_lines, output_samples), "view_shape");
          lines_pushed = 0;
        end
        if (in_intact && int'(in_samples) != input_samples)
          $fatal(1, "trm_decoder_model: a line of %0d samples where the view's lines have %0d", in_samples,
                 input_samples);
        if (input_samples > MAX_SAMPLES || output_samples > MAX_SAMPLES)
          $fatal(1, "trm_decoder_model: the view's lines (%0d in, %0d out samples) exceed MAX_SAMPLES = %0d",
                 input_samples, output_samples, MAX_SAMPLES);
        for (int i = 0; i < MAX_SAMPLES; i++) line_words[i] = int'(in_codes[i]);
        check(trm_dpi_push_line(decoder, line_words, int'(in_samples), int'(in_intact)), "push_line");
        lines_pushed = lines_pushed + 1;
        if (lines_pushed == input_lines) check(trm_dpi_end_view(decoder), "end_view");
      end
      if (!out_valid || out_ready) begin
        status = trm_dpi_pop_line(decoder, row, row_words, samples);
        if (status == TRM_OK && samples != output_samples)
          $fatal(1, "trm_decoder_model: a row of %0d samples where the view has %0d", samples, output_samples);
        check(status, "pop_line");
        out_valid <= status == TRM_OK;
        if (status == TRM_OK) begin
          out_row <= 16'(row);
          out_last <= row == output_lines - 1;
          out_samples <= 16'(samples);
          for (int i = 0; i < MAX_SAMPLES; i++) out_drive[i] <= 16'(row_words[i]);
        end
      end
      check(trm_dpi_lines_ready(decoder, ready_rows), "lines_ready");
      // begin_view drops rows not yet popped: the next view waits until this one's rows are all out.
      in_ready <= ready_rows < OUT_DEPTH && !(lines_pushed == input_lines && ready_rows > 0);
    end
  end
endmodule
