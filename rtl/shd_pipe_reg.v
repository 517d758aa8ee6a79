// shd_pipe_reg: an optional pipeline register (valid + data) that becomes a wire when
// Enable = 0, so a unit's latency is a parameter. valid resets to 0; data has no reset
// (it is only looked at while valid).
module shd_pipe_reg #(
  parameter integer Width  = 8,
  parameter integer Enable = 1
) (
  input  wire             clk_i,
  input  wire             rst_ni,
  input  wire             valid_i,
  input  wire [Width-1:0] data_i,
  output wire             valid_o,
  output wire [Width-1:0] data_o
);

  generate
    if (Enable != 0) begin : g_reg
      reg             valid_q;
      reg [Width-1:0] data_q;
      always @(posedge clk_i or negedge rst_ni) begin
        if (!rst_ni) valid_q <= 1'b0;
        else         valid_q <= valid_i;
      end
      always @(posedge clk_i) begin
        data_q <= data_i;
      end
      assign valid_o = valid_q;
      assign data_o  = data_q;
    end else begin : g_wire
      // clk_i and rst_ni are unused in this branch.
      wire unused_clk_rst = clk_i ^ rst_ni;
      assign valid_o = valid_i;
      assign data_o  = data_i;
    end
  endgenerate

endmodule
